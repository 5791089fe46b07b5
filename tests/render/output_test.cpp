// Headless output: numbered PNG frames, and an MP4 through ffmpeg when it is installed.
#include <filesystem>

#include "io/png_io.hpp"
#include "render/headless_output.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

Image<uchar3> frame(int w, int h, std::uint8_t shade) {
  return Image<uchar3>::from_host(std::vector<uchar3>(static_cast<std::size_t>(w) * h, uchar3{shade, 0, 0}), w, h,
                                  Device::CPU);
}

TEST(RenderOutput, FramesAreNumberedPngs) {
  RenderParams p;
  p.write_frames = true;
  const std::string dir = ::testing::TempDir() + "/seamless_render_frames";
  std::filesystem::remove_all(dir);
  HeadlessOutput out(dir, p);
  for (int i = 0; i < 3; ++i) out.add(frame(33, 21, static_cast<std::uint8_t>(50 * i)));
  out.finish();
  for (int i = 0; i < 3; ++i) {
    const Image<uchar3> im = read_png_rgb(dir + "/frames/00000" + std::to_string(i) + ".png");
    EXPECT_EQ(im.width(), 33);
    EXPECT_EQ(im.to_host()[0].x, 50 * i);
  }
}

// Odd sizes are padded for H.264's 4:2:0 sampling; the file must exist and be non-trivial.
TEST(RenderOutput, VideoThroughFfmpeg) {
  if (find_ffmpeg().empty()) GTEST_SKIP() << "ffmpeg is not installed (apt-get install ffmpeg)";
  RenderParams p;
  p.video = true;
  const std::string dir = ::testing::TempDir() + "/seamless_render_video";
  std::filesystem::remove_all(dir);
  HeadlessOutput out(dir, p);
  for (int i = 0; i < 10; ++i) out.add(frame(33, 21, static_cast<std::uint8_t>(20 * i)));
  EXPECT_TRUE(out.video_open());
  out.finish();
  ASSERT_TRUE(std::filesystem::exists(out.video_path()));
  EXPECT_GT(std::filesystem::file_size(out.video_path()), 200u);
}

}  // namespace
}  // namespace seamless::test
