// PNG I/O: round trips of every supported format and clear errors for bad files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/png_io.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {

template <class T, class F> Image<T> make_image(int w, int h, F value) {
  std::vector<T> v(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) v[y * w + x] = value(x, y);
  return Image<T>::from_host(v, w, h, Device::CPU);
}

template <class F> void expect_error_containing(F fn, const std::string& needle) {
  try {
    fn();
    FAIL() << "expected seamless::Error containing '" << needle << "'";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(Png, RoundTripU16KeepsEveryValue) {
  TmpDir dir("png16");
  // Values spanning the whole 16-bit range, including bytes that would swap visibly.
  auto im = make_image<std::uint16_t>(37, 11,
                                      [](int x, int y) { return static_cast<std::uint16_t>(x * 1771 + y * 313 + 1); });
  write_png_u16(dir / "a.png", im);
  PngInfo info = png_info(dir / "a.png");
  EXPECT_EQ(info.width, 37);
  EXPECT_EQ(info.height, 11);
  EXPECT_EQ(info.bit_depth, 16);
  EXPECT_EQ(info.channels, 1);
  EXPECT_EQ(read_png_u16(dir / "a.png").to_host(), im.to_host());
}

TEST(Png, RoundTripU8AndRgb) {
  TmpDir dir("png8");
  auto g = make_image<std::uint8_t>(20, 9, [](int x, int y) { return static_cast<std::uint8_t>(x * 13 + y * 7); });
  auto c = make_image<uchar3>(20, 9, [](int x, int y) {
    return uchar3{static_cast<std::uint8_t>(x * 12), static_cast<std::uint8_t>(y * 28),
                  static_cast<std::uint8_t>(x ^ y)};
  });
  write_png_u8(dir / "g.png", g);
  write_png_rgb(dir / "c.png", c);
  EXPECT_EQ(read_png_u8(dir / "g.png").to_host(), g.to_host());
  auto back = read_png_rgb(dir / "c.png").to_host();
  auto want = c.to_host();
  ASSERT_EQ(back.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i)
    ASSERT_TRUE(back[i].x == want[i].x && back[i].y == want[i].y && back[i].z == want[i].z) << i;
  // Gray is promoted to RGB on request (R = G = B).
  auto promoted = read_png_rgb(dir / "g.png").to_host();
  EXPECT_EQ(promoted[5].x, g.to_host()[5]);
  EXPECT_EQ(promoted[5].z, g.to_host()[5]);
}

TEST(Png, MissingFileNamesTheFile) {
  expect_error_containing([] { read_png_u16("/nonexistent/dir/depth.png"); }, "/nonexistent/dir/depth.png");
}

TEST(Png, TruncatedFileIsAnError) {
  TmpDir dir("pngtrunc");
  auto im = make_image<std::uint16_t>(64, 64, [](int x, int y) { return static_cast<std::uint16_t>(x * y * 17); });
  write_png_u16(dir / "full.png", im);
  auto size = std::filesystem::file_size(dir / "full.png");
  std::filesystem::copy_file(dir / "full.png", dir / "cut.png");
  std::filesystem::resize_file(dir / "cut.png", size / 2);
  expect_error_containing([&] { read_png_u16(dir / "cut.png"); }, "truncated or corrupt");
  std::filesystem::resize_file(dir / "cut.png", 4);
  expect_error_containing([&] { read_png_u16(dir / "cut.png"); }, "not a PNG");
}

TEST(Png, WrongBitDepthIsAnError) {
  TmpDir dir("pngdepth");
  write_png_u8(dir / "g8.png", make_image<std::uint8_t>(4, 4, [](int, int) { return std::uint8_t{9}; }));
  expect_error_containing([&] { read_png_u16(dir / "g8.png"); }, "8-bit grayscale, expected 16-bit");
  write_png_rgb(dir / "c.png", make_image<uchar3>(4, 4, [](int, int) { return uchar3{1, 2, 3}; }));
  expect_error_containing([&] { read_png_u8(dir / "c.png"); }, "8-bit RGB, expected 8-bit grayscale");
}
