// Bad TUM folders: each gives a seamless::Error naming the file, or with skip_bad_frames a skipped,
// counted frame.
#include <gtest/gtest.h>

#include <spdlog/sinks/ostream_sink.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "io/input_params.hpp"
#include "io/png_io.hpp"
#include "io/record.hpp"
#include "io/synthetic_source.hpp"
#include "io/tum_source.hpp"
#include "tmp_dir.hpp"

using namespace seamless;
namespace fs = std::filesystem;

namespace {

// A valid 3-frame TUM folder from the synthetic room (noise off: every depth in range).
void make_folder(const TmpDir& dir) {
  InputParams p;
  p.synthetic.frames = 3;
  p.synthetic.noise = false;
  SyntheticSource src(p);
  record(src, dir.str());
}

InputParams tum(const TmpDir& dir, bool skip = false) {
  InputParams p;
  p.source = InputSource::tum;
  p.path = dir.str();
  p.skip_bad_frames = skip;
  return p;
}

std::vector<std::string> lines(const std::string& path) {
  std::ifstream in(path);
  std::vector<std::string> out;
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

void write_lines(const std::string& path, const std::vector<std::string>& ls) {
  std::ofstream out(path);
  for (const auto& l : ls) out << l << '\n';
}

std::string second_depth_file(const TmpDir& dir) {
  return (dir.path / TumSource(tum(dir)).pairs()[1].depth.file).string();
}

// Reads every frame; returns the error message ("" when none).
std::string read_all(const InputParams& p, std::int64_t* frames = nullptr, std::int64_t* skipped = nullptr) {
  try {
    TumSource src(p);
    RgbdFrame f;
    std::int64_t n = 0;
    while (src.next(f)) ++n;
    if (frames) *frames = n;
    if (skipped) *skipped = src.skipped_frames();
    return "";
  } catch (const Error& e) {
    return e.what();
  }
}

}  // namespace

TEST(BadInput, MissingListFile) {
  TmpDir dir("bad_list");
  make_folder(dir);
  fs::remove(dir / "associations.txt");
  fs::remove(dir / "depth.txt");
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, "depth.txt");
  EXPECT_MENTIONS(msg, "cannot open");
}

TEST(BadInput, MissingFolder) {
  InputParams p;
  p.source = InputSource::tum;
  p.path = "/nonexistent/rgbd_dataset_freiburg1_xyz";
  EXPECT_MENTIONS(read_all(p), "/nonexistent/rgbd_dataset_freiburg1_xyz");
}

TEST(BadInput, MissingPngFailsOrIsSkipped) {
  TmpDir dir("bad_missing");
  make_folder(dir);
  std::string victim = second_depth_file(dir);
  fs::remove(victim);
  EXPECT_MENTIONS(read_all(tum(dir)), victim);
  std::int64_t n = 0, skipped = 0;
  EXPECT_EQ(read_all(tum(dir, true), &n, &skipped), "");
  EXPECT_EQ(n, 2);
  EXPECT_EQ(skipped, 1);
}

TEST(BadInput, TruncatedPngFailsOrIsSkipped) {
  TmpDir dir("bad_trunc");
  make_folder(dir);
  std::string victim = second_depth_file(dir);
  fs::resize_file(victim, fs::file_size(victim) / 3);
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, victim);
  EXPECT_MENTIONS(msg, "truncated");
  std::int64_t n = 0, skipped = 0;
  EXPECT_EQ(read_all(tum(dir, true), &n, &skipped), "");
  EXPECT_EQ(skipped, 1);
}

TEST(BadInput, EightBitDepthImage) {
  TmpDir dir("bad_8bit");
  make_folder(dir);
  std::string victim = second_depth_file(dir);
  Image<std::uint8_t> g(640, 480, Device::CPU);
  g.buffer().zero();
  write_png_u8(victim, g);
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, victim);
  EXPECT_MENTIONS(msg, "8-bit grayscale, expected 16-bit");
}

TEST(BadInput, WrongDepthScaleIsAlwaysAnError) {
  TmpDir dir("bad_scale");
  make_folder(dir);
  // Depth written at 5000/m read as if it were millimetres: a median of ~10 m, implausible.
  InputParams p = tum(dir, true);  // not a bad frame but a bad setting: skipping does not hide it
  p.depth_scale = 1000;
  std::string msg = read_all(p);
  EXPECT_MENTIONS(msg, "median depth");
  EXPECT_MENTIONS(msg, "input.depth_scale");
  EXPECT_MENTIONS(msg, ".png");
}

TEST(BadInput, TimestampsOutOfOrder) {
  TmpDir dir("bad_order");
  make_folder(dir);
  auto ls = lines(dir / "associations.txt");
  ASSERT_EQ(ls.size(), 3u);
  std::swap(ls[1], ls[2]);
  write_lines(dir / "associations.txt", ls);
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, "associations.txt");
  EXPECT_MENTIONS(msg, "out of order");
  EXPECT_MENTIONS(msg, "line 3");
}

TEST(BadInput, FolderWithNoPairs) {
  TmpDir dir("bad_nopairs");
  make_folder(dir);
  fs::remove(dir / "associations.txt");
  // Depth stamps shifted by 0.5 s: nothing within associate.py's 0.02 s.
  auto ls = lines(dir / "depth.txt");
  for (auto& l : ls)
    if (l[0] != '#') l = std::to_string(std::stod(l) + 0.5) + l.substr(l.find(' '));
  write_lines(dir / "depth.txt", ls);
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, dir.str());
  EXPECT_MENTIONS(msg, "no rgb/depth pairs");
}

TEST(BadInput, MalformedListLine) {
  TmpDir dir("bad_malformed");
  make_folder(dir);
  std::ofstream(dir / "associations.txt", std::ios::app) << "0.5 rgb/only_two_fields.png\n";
  std::string msg = read_all(tum(dir));
  EXPECT_MENTIONS(msg, "associations.txt");
  EXPECT_MENTIONS(msg, "line 4");
}

// A line repeated in a TUM list (same timestamp twice) made one frame two, fused twice
// with two poses at one time. It is dropped, with a warning naming the file and line.
TEST(BadInput, RepeatedListLinesAreDroppedWithAWarning) {
  TmpDir dir("bad_repeat");
  make_folder(dir);
  for (const char* list : {"rgb.txt", "depth.txt", "associations.txt"}) {
    auto ls = lines(dir / list);
    std::size_t first = 0;
    while (ls[first][0] == '#') ++first;
    ls.insert(ls.begin() + first + 1, ls[first + 1]);  // the second frame's line twice
    write_lines(dir / list, ls);
  }
  std::ostringstream log;
  auto logger = std::make_shared<spdlog::logger>("test", std::make_shared<spdlog::sinks::ostream_sink_mt>(log));
  auto previous = spdlog::default_logger();
  spdlog::set_default_logger(logger);
  const auto depth = read_tum_list(dir / "depth.txt");
  spdlog::set_default_logger(previous);
  ASSERT_EQ(depth.size(), 3u);  // the folder's 3 frames, each once
  EXPECT_LT(depth[0].timestamp, depth[1].timestamp);
  EXPECT_LT(depth[1].timestamp, depth[2].timestamp);
  // depth.txt: 3 comment lines, frame 0 on line 4, frame 1 on lines 5 and 6.
  EXPECT_MENTIONS(log.str(), "depth.txt' line 6");
  EXPECT_MENTIONS(log.str(), "repeats the line before it; line dropped");
  for (Association association : {Association::automatic, Association::file}) {
    InputParams p = tum(dir);
    p.association = association;
    std::int64_t n = 0;
    EXPECT_EQ(read_all(p, &n), "") << enum_name(association);
    EXPECT_EQ(n, 3) << enum_name(association);
  }
}

// The readers' errors are InputErrors, so that `seamless` exits with its input-error code.
TEST(BadInput, ReadersThrowInputErrors) {
  TmpDir dir("bad_kind");
  make_folder(dir);
  fs::resize_file(second_depth_file(dir), 20);
  TumSource src(tum(dir));
  RgbdFrame f;
  EXPECT_TRUE(src.next(f));
  EXPECT_THROW(src.next(f), InputError);
  InputParams missing = tum(dir);
  missing.path = dir / "nowhere";
  EXPECT_THROW(TumSource{missing}, InputError);
}
