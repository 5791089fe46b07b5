// TUM rgb/depth association (input.association): TUM's associate.py rule on hand-made lists, and
// which pairing a folder's frames use when an association file is present.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/input_params.hpp"
#include "io/tum_source.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {

std::vector<TumListEntry> list(const std::vector<double>& stamps, const std::string& kind) {
  std::vector<TumListEntry> out;
  for (double t : stamps) out.push_back({t, kind + "/" + std::to_string(t) + ".png"});
  return out;
}

void write_list(const std::string& path, const std::vector<TumListEntry>& l) {
  std::ofstream out(path);
  out << "# timestamp filename\n";
  out.precision(17);
  for (const auto& e : l) out << e.timestamp << ' ' << e.file << '\n';
}

// Stamps as TUM writes them (microseconds on a 1.3e9 s clock): differences exact to ~1e-7 s in
// double, far below the millisecond margins used here.
constexpr double kT0 = 1305031453.0;

}  // namespace

TEST(Association, ExactPairsKeepRgbOrder) {
  auto rgb = list({kT0 + 0.000, kT0 + 0.033, kT0 + 0.066}, "rgb");
  auto depth = list({kT0 + 0.005, kT0 + 0.030, kT0 + 0.070}, "depth");
  auto pairs = associate(rgb, depth);
  ASSERT_EQ(pairs.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(pairs[i].rgb.file, rgb[i].file);
    EXPECT_EQ(pairs[i].depth.file, depth[i].file);
  }
}

TEST(Association, StampBeyondMaxDifferenceIsLeftOut) {
  // 0.019 s is paired, 0.021 s is not (max_difference 0.02 s, strict like associate.py).
  auto rgb = list({kT0, kT0 + 1.0}, "rgb");
  auto depth = list({kT0 + 0.019, kT0 + 1.021}, "depth");
  auto pairs = associate(rgb, depth);
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].rgb.file, rgb[0].file);
  // A larger window takes the second one too.
  EXPECT_EQ(associate(rgb, depth, 0.03).size(), 2u);
}

TEST(Association, GreedyEachStampOnce) {
  // Both rgb frames are within 0.02 s of the middle depth frame; the closer one (0.002 s) takes it,
  // the other falls back to its own next-best depth (0.015 s), and the depth frame is used once.
  auto rgb = list({kT0 + 0.000, kT0 + 0.012}, "rgb");
  auto depth = list({kT0 - 0.015, kT0 + 0.010}, "depth");
  auto pairs = associate(rgb, depth);
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].rgb.file, rgb[0].file);
  EXPECT_EQ(pairs[0].depth.file, depth[0].file);
  EXPECT_EQ(pairs[1].rgb.file, rgb[1].file);
  EXPECT_EQ(pairs[1].depth.file, depth[1].file);
  // With only the contested depth frame, one rgb frame stays unpaired.
  auto single = associate(rgb, list({kT0 + 0.010}, "depth"));
  ASSERT_EQ(single.size(), 1u);
  EXPECT_EQ(single[0].rgb.file, rgb[1].file);
}

TEST(Association, OffsetIsAddedToDepthStamps) {
  // Depth 0.5 s late on its own clock: nothing pairs, until offset -0.5 s shifts it back.
  auto rgb = list({kT0, kT0 + 0.033}, "rgb");
  auto depth = list({kT0 + 0.503, kT0 + 0.536}, "depth");
  EXPECT_TRUE(associate(rgb, depth).empty());
  EXPECT_EQ(associate(rgb, depth, 0.02, -0.5).size(), 2u);
}

TEST(Association, FolderPairsByTimeUnlessAskedForTheFile) {
  TmpDir dir("assoc_folder");
  auto rgb = list({kT0, kT0 + 0.033, kT0 + 0.066}, "rgb");
  auto depth = list({kT0 + 0.004, kT0 + 0.037, kT0 + 0.070}, "depth");
  write_list(dir / "rgb.txt", rgb);
  write_list(dir / "depth.txt", depth);
  std::ofstream(dir / "associate.txt") << std::fixed << rgb[0].timestamp << ' ' << rgb[0].file << ' '
                                       << depth[0].timestamp << ' ' << depth[0].file << '\n';
  InputParams p;
  p.source = InputSource::tum;
  p.path = dir.str();
  EXPECT_EQ(tum_folder_pairs(dir.str(), p).size(), 3u);  // auto: by time, the partial file ignored
  p.association = Association::file;
  EXPECT_EQ(tum_folder_pairs(dir.str(), p).size(), 1u);
  std::filesystem::remove(dir / "associate.txt");
  try {
    tum_folder_pairs(dir.str(), p);
    ADD_FAILURE() << "association: file without a file must fail";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("input.association"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(dir.str()), std::string::npos) << e.what();
  }
}
