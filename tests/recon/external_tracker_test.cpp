// The external trackers of the comparison (src/recon/external/: OpenCV contrib's rgbd odometries,
// PCL's GICP) driven by TrackingSession over the synthetic room without sensor noise, against the
// exact ground truth. Each case skips, naming the module, when its library is not in the build.
#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>

#include "core/error.hpp"
#include "tracker_test_util.hpp"

using namespace seamless;

namespace {

// 20 frames of the orbit (15 deg/s at 30 fps, radius 1.6 m): the camera travels about 0.28 m and
// turns about 10 degrees, surfaces 1.5-3 m away.
constexpr int kFrames = 20;

// The ATE bound, derived: with exact depth, what is left is each frame's alignment error e, which
// frame-to-frame odometry accumulates; a drift growing as k e over frames k = 0..N has an RMS of
// about N e / sqrt(3) before any alignment (the Horn/Umeyama alignment of eval can only lower it).
// For trackers working on full-resolution pixels we ask e <= 1 mm a frame: a quarter of the 4 mm
// footprint of one pixel at 2 m (f = 525 px), i.e. sub-pixel registration, which any of these
// methods reaches on noise-free depth over >= 10^4 correspondences. GICP sees the scene through a
// 2 cm voxel grid whose centroids shift with the viewpoint: we allow a tenth of a voxel, 2 mm.
double ate_bound(double per_frame_error_m) { return kFrames * per_frame_error_m / std::sqrt(3.0); }

struct ExternalCase {
  std::string kind;
  std::string module;  // named in the skip message
  double per_frame_error_m;
};

void PrintTo(const ExternalCase& c, std::ostream* os) { *os << c.kind; }  // readable ctest names

class ExternalTracker : public ::testing::TestWithParam<ExternalCase> {};

TEST_P(ExternalTracker, NoiseFreeSyntheticRoomWithinDerivedBound) {
  const ExternalCase& c = GetParam();
  bool available = false;
  for (const TrackerInfo& t : tracker_registry())
    if (t.kind == c.kind) available = t.available;
  if (!available) GTEST_SKIP() << c.kind << ": " << c.module << " is not in this build";

  auto src = make_source(test::synthetic_input(kFrames, /*noise=*/false));
  TrackSequenceParams p;
  p.tracker.kind = c.kind;
  p.write_files = false;
  auto t = test::track_with_gt(*src, p, Device::CPU, "");
  ASSERT_EQ(t.result.trajectory.size(), static_cast<std::size_t>(kFrames));
  EXPECT_EQ(t.result.lost_frames, 0);
  for (const FrameRecord& r : t.result.frames) EXPECT_FALSE(r.fused) << "no volume was given: nothing to fuse into";
  AteResult ate = compute_ate(t.result.trajectory, t.gt);
  EXPECT_LE(ate.trans.rmse, ate_bound(c.per_frame_error_m)) << c.kind;
  RecordProperty("ate_rmse_m", std::to_string(ate.trans.rmse));
}

INSTANTIATE_TEST_SUITE_P(
    Libraries, ExternalTracker,
    ::testing::Values(ExternalCase{"opencv_rgbd_odometry", "OpenCV rgbd (libopencv-contrib-dev)", 0.001},
                      ExternalCase{"opencv_icp", "OpenCV rgbd (libopencv-contrib-dev)", 0.001},
                      ExternalCase{"opencv_rgbd_icp", "OpenCV rgbd (libopencv-contrib-dev)", 0.001},
                      ExternalCase{"opencv_fast_icp", "OpenCV rgbd (libopencv-contrib-dev)", 0.001},
                      ExternalCase{"pcl_gicp", "PCL (libpcl-dev)", 0.002}),
    [](const ::testing::TestParamInfo<ExternalCase>& i) { return i.param.kind; });

TEST(ExternalTrackerRegistry, EveryKindIsAvailableOrSaysWhatToInstall) {
  int external = 0;
  for (const TrackerInfo& t : tracker_registry()) {
    if (!t.make_external) {
      EXPECT_TRUE(t.available || !t.missing.empty()) << t.kind;
      continue;
    }
    ++external;
    EXPECT_TRUE(t.available) << t.kind << ": a factory is compiled in only when its library is";
  }
  for (const TrackerInfo& t : tracker_registry())
    if (!t.available) {
      EXPECT_NE(t.missing.find("apt-get install"), std::string::npos) << t.kind << ": " << t.missing;
      try {
        require_tracker(t.kind);
        ADD_FAILURE() << t.kind << " is not available but require_tracker accepted it";
      } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("not available in this build"), std::string::npos) << e.what();
      }
    }
  RecordProperty("external_trackers_built", std::to_string(external));
}

TEST(ExternalTrackerRegistry, UnknownKindListsTheKnownOnes) {
  try {
    require_tracker("opencv_rgbd");  // the name before the rename to opencv_rgbd_icp / opencv_rgbd_odometry
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("opencv_rgbd_icp"), std::string::npos) << e.what();
  }
}

}  // namespace
