// input.depth_scale checked against the depth images' content: the Kinect v1's disparity steps
// (src/io/depth_scale.hpp), on real TUM data, the real frame folder and synthetic sensors.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "io/depth_scale.hpp"
#include "io/frame_folder_source.hpp"
#include "io/input_params.hpp"
#include "io/png_io.hpp"
#include "io/tum_source.hpp"
#include "kernels/io/render_room.hpp"
#include "tmp_dir.hpp"

using namespace seamless;
namespace fs = std::filesystem;

namespace {

const char* kTum = "tum_fr1_rpy_000-149";
// The first depth image of the TUM folder (depth.txt's first entry).
std::string first_tum_depth() { return data_dir(kTum) + "/depth/1305031229.528784.png"; }

// The per-device calibration of a Kinect's IR focal length and baseline varies by a percent or two
// around the nominal 580 px / 7.5 cm the check uses (Smisek et al. 2011 measured 585.6 px): 3%.
constexpr double kKinectTolerance = 0.03;

// A 640x480 view of a floor-like plane receding from 0.8 m to 3.5 m (depth linear in the row),
// measured by a triangulating sensor with disparity steps of `step` pixels and focal length x
// baseline fb (kinect_quantise, the synthetic room's model), stored at `scale` units per metre.
// fb = 580 * 0.075, step 1/8: a Kinect v1.
Image<std::uint16_t> quantised_plane(double scale, float fb, float step) {
  Image<std::uint16_t> im(640, 480, Device::CPU);
  kernels::DepthNoise n;
  n.baseline = 1.f;  // f b folded into f below
  n.disparity_step = step;
  for (int y = 0; y < 480; ++y)
    for (int x = 0; x < 640; ++x) {
      float z = 0.8f + 2.7f * (y + x / 640.f) / 480.f;  // every depth once: no gaps in the scene
      float zq = kernels::kinect_quantise(z, fb, n, 0.f);
      im.buffer().data()[y * 640 + x] = static_cast<std::uint16_t>(std::lround(zq * scale));
    }
  return im;
}

}  // namespace

TEST(DepthScale, RealTumStepsSayFiveThousand) {
  REQUIRE_DATA(data_dir(kTum));
  const Image<std::uint16_t> raw = read_png_u16(first_tum_depth());
  const DepthQuantisation q = depth_quantisation(raw);
  ASSERT_TRUE(q.informative);
  EXPECT_GT(q.steps, 100);
  EXPECT_NEAR(q.kinect_scale, 5000, 5000 * kKinectTolerance);
  EXPECT_EQ(judge_depth_scale(q, 5000, "f").kind, DepthScaleVerdict::consistent);
  // TUM's depth read as millimetres: the median is a plausible 6 m, but the steps are 5x too fine
  // for that range. Both a Kinect's geometry and TUM's convention agree: a config error.
  const DepthScaleVerdict v = judge_depth_scale(q, 1000, "first.png");
  EXPECT_EQ(v.kind, DepthScaleVerdict::wrong);
  EXPECT_EQ(v.likely_scale, 5000);
  EXPECT_MENTIONS(v.message, "input.depth_scale: 5000");
  EXPECT_MENTIONS(v.message, "first.png");
}

TEST(DepthScale, RealKinectDepthInMillimetresSaysOneThousand) {
  // The same Kinect frame written the way 7-Scenes and OpenNI tools do (millimetres): each value
  // divided by 5 and rounded. The steps (3 mm at 1 m, 12 mm at 2 m) survive the rounding.
  REQUIRE_DATA(data_dir(kTum));
  Image<std::uint16_t> raw = read_png_u16(first_tum_depth());
  for (std::int64_t i = 0; i < raw.buffer().size(); ++i)
    raw.buffer().data()[i] = static_cast<std::uint16_t>(std::lround(raw.buffer().data()[i] / 5.0));
  const DepthQuantisation q = depth_quantisation(raw);
  ASSERT_TRUE(q.informative);
  EXPECT_NEAR(q.kinect_scale, 1000, 1000 * kKinectTolerance);
  EXPECT_EQ(judge_depth_scale(q, 1000, "f").kind, DepthScaleVerdict::consistent);
  const DepthScaleVerdict v = judge_depth_scale(q, 5000, "f");  // millimetres read as TUM: 5x too near
  EXPECT_EQ(v.kind, DepthScaleVerdict::wrong);
  EXPECT_EQ(v.likely_scale, 1000);
}

TEST(DepthScale, TumSourceStopsOnMillimetresAndIsSilentOnItsOwnScale) {
  REQUIRE_DATA(data_dir(kTum));
  InputParams p;
  p.source = InputSource::tum;
  p.path = data_dir(kTum);
  p.max_frames = 12;
  auto read_all = [](const InputParams& params) -> std::string {
    try {
      TumSource src(params);
      RgbdFrame f;
      while (src.next(f)) {
      }
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_EQ(read_all(p), "");  // depth_scale 0: TUM's 5000
  p.depth_scale = 5000;
  EXPECT_EQ(read_all(p), "");
  p.depth_scale = 1000;
  p.skip_bad_frames = true;  // a setting, not a bad frame: skipping does not hide it
  const std::string msg = read_all(p);
  EXPECT_MENTIONS(msg, "input.depth_scale 1000 contradicts the depth images");
  EXPECT_MENTIONS(msg, "set input.depth_scale: 5000");
  EXPECT_MENTIONS(msg, "1305031229.528784.png");
  // The median alone would have let it through (6 m is a plausible depth): the check is the only guard.
  p.check_depth_scale = false;
  EXPECT_EQ(read_all(p), "");
}

TEST(DepthScale, RealFrameFolderIsNotMeasurableAndPasses) {
  // frames_box_50: a camera 0.4 m from the objects, millimetres. At 0.4 m a Kinect step is 0.46 mm,
  // below the PNG's 1 mm unit: every integer occurs, the steps say nothing, nothing is reported.
  const std::string dir = data_dir("frames_box_50");
  REQUIRE_DATA(dir);
  const DepthQuantisation q = depth_quantisation(read_png_u16(dir + "/frame-000015.depth.png"));
  EXPECT_FALSE(q.informative);
  EXPECT_LE(q.median_gap, 1.0);
  EXPECT_EQ(judge_depth_scale(q, 1000, "f").kind, DepthScaleVerdict::not_measurable);
  InputParams p;
  p.source = InputSource::frames;
  p.path = dir;
  p.depth_scale = 1000;
  FrameFolderSource src(p);
  RgbdFrame f;
  int n = 0;
  while (src.next(f)) ++n;
  EXPECT_EQ(n, 50);
}

TEST(DepthScale, SyntheticKinectAtBothScales) {
  const float kinect_fb = 580.f * 0.075f;
  for (double scale : {5000.0, 1000.0}) {
    const DepthQuantisation q = depth_quantisation(quantised_plane(scale, kinect_fb, 0.125f));
    ASSERT_TRUE(q.informative) << scale;
    // The model is the check's own geometry: only the 16-bit rounding and the median remain (1%).
    EXPECT_NEAR(q.kinect_scale, scale, 0.01 * scale);
    EXPECT_EQ(judge_depth_scale(q, scale, "f").kind, DepthScaleVerdict::consistent);
  }
}

TEST(DepthScale, OtherCamerasAreWarnedAboutOrLeftAlone) {
  // A stereo camera with finer steps (RealSense D400-like: 1/32-pixel disparity, f 600 px, b 5 cm:
  // steps 0.36x a Kinect's) in millimetres: the steps look like a Kinect at ~360 units per metre.
  // That is 0.36x the configured 1000 but no common file convention: a warning, not an error.
  const DepthQuantisation q = depth_quantisation(quantised_plane(1000, 600.f * 0.05f, 1.f / 32));
  ASSERT_TRUE(q.informative);
  const DepthScaleVerdict v = judge_depth_scale(q, 1000, "d4xx.png");
  EXPECT_EQ(v.kind, DepthScaleVerdict::doubtful);
  EXPECT_MENTIONS(v.message, "may be wrong");
  // A time-of-flight camera: no disparity steps, depth continuous to the PNG's millimetre.
  Image<std::uint16_t> tof(640, 480, Device::CPU);
  for (int i = 0; i < 640 * 480; ++i) tof.buffer().data()[i] = static_cast<std::uint16_t>(800 + i / 100);
  EXPECT_FALSE(depth_quantisation(tof).informative);
  // Nothing to see: an empty depth image.
  Image<std::uint16_t> none(64, 48, Device::CPU);
  none.buffer().zero();
  EXPECT_EQ(judge_depth_scale(depth_quantisation(none), 1000, "f").kind, DepthScaleVerdict::not_measurable);
}
