// JPEG colour (libjpeg): decoding against the PNG it was made from, detection by content, errors,
// and TUM folders whose colour images are JPEG.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>

#include "core/error.hpp"
#include "io/input_params.hpp"
#include "io/jpeg_io.hpp"
#include "io/png_io.hpp"
#include "io/record.hpp"
#include "io/synthetic_source.hpp"
#include "io/tum_source.hpp"
#include "tmp_dir.hpp"

using namespace seamless;
namespace fs = std::filesystem;

namespace {

// ITU-R BT.601 luma, the Y that JPEG (JFIF) codes at full resolution.
double luma(uchar3 c) { return 0.299 * c.x + 0.587 * c.y + 0.114 * c.z; }

struct Diff {
  double luma_rms = 0, luma_max = 0, rgb_rms = 0;
};
Diff compare(const Image<uchar3>& a, const Image<uchar3>& b) {
  Diff d;
  const std::int64_t n = a.buffer().size();
  double sl = 0, sc = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    uchar3 p = a.buffer().data()[i], q = b.buffer().data()[i];
    double dl = luma(p) - luma(q);
    sl += dl * dl;
    d.luma_max = std::max(d.luma_max, std::fabs(dl));
    sc += (double(p.x) - q.x) * (double(p.x) - q.x) + (double(p.y) - q.y) * (double(p.y) - q.y) +
          (double(p.z) - q.z) * (double(p.z) - q.z);
  }
  d.luma_rms = std::sqrt(sl / n);
  d.rgb_rms = std::sqrt(sc / (3.0 * n));
  return d;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Jpeg, RealImageDecodesWithinQuantisationError) {
  const std::string png = data_dir("frames_box_50") + "/frame-000015.color.png";
  REQUIRE_DATA(data_dir("frames_box_50"));
  TmpDir dir("jpeg_real");
  const Image<uchar3> original = read_png_rgb(png);
  // Quality 100: every quantisation step is 1, so each DCT coefficient is off by at most 1/2 (plus
  // libjpeg's fixed-point DCT rounding); the DCT is orthonormal, so the luma error per pixel has the
  // RMS of one coefficient's rounding, 1/sqrt(12) = 0.29 levels, plus the rounding of the colour
  // conversion to 8-bit YCbCr and back (again ~0.3 each). Luma is coded at full resolution; the
  // 4:2:0 chroma subsampling does not change luma except where the decoded RGB clips at 0 or 255.
  // So: luma RMS below 1 level, and no pixel off by more than a few (8 allows for the clipping).
  write_jpeg_rgb(dir / "q100.jpg", original, 100);
  const Image<uchar3> q100 = read_jpeg_rgb(dir / "q100.jpg");
  ASSERT_EQ(q100.width(), original.width());
  ASSERT_EQ(q100.height(), original.height());
  Diff d = compare(original, q100);
  EXPECT_LT(d.luma_rms, 1.0);
  EXPECT_LE(d.luma_max, 8.0);
  // Colour at quality 90 (what exporters write): the same picture. The error is dominated by halved
  // chroma resolution at colour edges, a few levels RMS on a photograph; a swapped channel or a
  // shifted row would be tens of levels.
  write_jpeg_rgb(dir / "q90.jpg", original, 90);
  d = compare(original, read_jpeg_rgb(dir / "q90.jpg"));
  EXPECT_LT(d.rgb_rms, 8.0);
  EXPECT_GT(fs::file_size(dir / "q100.jpg"), fs::file_size(dir / "q90.jpg"));  // really re-encoded
}

TEST(Jpeg, FormatIsToldByContentNotByName) {
  TmpDir dir("jpeg_content");
  Image<uchar3> im(32, 16, Device::CPU);
  for (int i = 0; i < 32 * 16; ++i) im.buffer().data()[i] = {std::uint8_t(i % 32 * 8), std::uint8_t(i / 32 * 16), 77};
  write_jpeg_rgb(dir / "really_jpeg.png", im, 95);
  write_png_rgb(dir / "really_png.jpg", im);
  EXPECT_EQ(image_format(dir / "really_jpeg.png"), ImageFormat::jpeg);
  EXPECT_EQ(image_format(dir / "really_png.jpg"), ImageFormat::png);
  const std::vector<uchar3> from_png = read_colour_image(dir / "really_png.jpg").to_host();
  for (std::size_t i = 0; i < from_png.size(); ++i) EXPECT_EQ(from_png[i].x, im.buffer().data()[i].x);  // lossless
  const std::vector<uchar3> a = read_colour_image(dir / "really_jpeg.png").to_host(),
                            b = read_jpeg_rgb(dir / "really_jpeg.png").to_host();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].y, b[i].y);
}

TEST(Jpeg, BrokenFilesAreErrorsNamingTheFile) {
  TmpDir dir("jpeg_broken");
  Image<uchar3> im(64, 64, Device::CPU);
  for (int i = 0; i < 64 * 64; ++i)
    im.buffer().data()[i] = {std::uint8_t(i * 7), std::uint8_t(i * 13), std::uint8_t(i)};
  const std::string whole = dir / "whole.jpg", cut = dir / "cut.jpg";
  write_jpeg_rgb(whole, im, 90);
  // Half the file: libjpeg pads the missing rows with grey and warns; that must not pass as data.
  std::ifstream in(whole, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::ofstream(cut, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  std::string msg = error_of([&] { read_colour_image(cut); });
  EXPECT_MENTIONS(msg, cut);
  EXPECT_MENTIONS(msg, "truncated");
  // Only the start-of-image marker: libjpeg itself gives up.
  std::ofstream(dir / "stub.jpg", std::ios::binary).write(bytes.data(), 4);
  EXPECT_MENTIONS(error_of([&] { read_jpeg_rgb(dir / "stub.jpg"); }), "stub.jpg");
  std::ofstream(dir / "text.jpg") << "not an image";
  msg = error_of([&] { read_colour_image(dir / "text.jpg"); });
  EXPECT_MENTIONS(msg, "text.jpg");
  EXPECT_MENTIONS(msg, "neither PNG nor JPEG");
  EXPECT_MENTIONS(error_of([&] { read_colour_image(dir / "absent.jpg"); }), "cannot open");
  EXPECT_MENTIONS(error_of([&] { write_jpeg_rgb(dir / "q.jpg", im, 0); }), "quality 0");
}

TEST(Jpeg, TumFolderWithJpegColour) {
  // A TUM folder as other tools export it: rgb/*.jpg listed in rgb.txt.
  TmpDir dir("jpeg_tum");
  InputParams sp;
  sp.synthetic.frames = 3;
  sp.synthetic.noise = false;
  SyntheticSource synth(sp);
  record(synth, dir.str());
  auto rewrite = [&](const std::string& list) {
    std::ifstream in(dir / list);
    std::string out, line;
    while (std::getline(in, line)) {
      const std::size_t at = line.find("rgb/"), dot = line.find(".png", at);
      if (at != std::string::npos && dot != std::string::npos) {
        const std::string png = line.substr(at, dot + 4 - at), jpg = png.substr(0, png.size() - 4) + ".jpg";
        if (!fs::exists(dir / jpg)) write_jpeg_rgb(dir / jpg, read_png_rgb(dir / png), 100);
        line.replace(at, png.size(), jpg);
      }
      out += line + "\n";
    }
    std::ofstream(dir / list) << out;
  };
  rewrite("rgb.txt");
  rewrite("associations.txt");
  for (const auto& e : fs::directory_iterator(dir.path / "rgb"))
    if (e.path().extension() == ".png") fs::remove(e.path());
  InputParams p;
  p.source = InputSource::tum;
  p.path = dir.str();
  TumSource src(p);
  SyntheticSource again(sp);
  RgbdFrame f, g;
  int n = 0;
  while (src.next(f)) {
    ASSERT_TRUE(again.next(g));
    // Quality 100 of a rendered room: luma within JPEG's rounding (RealImageDecodesWithinQuantisationError).
    EXPECT_LT(compare(g.rgb, f.rgb).luma_rms, 1.0);
    ++n;
  }
  EXPECT_EQ(n, 3);
}
