// Whole tracked sequences against ground truth: the synthetic room (noisy Kinect model), a cut in
// the sequence (tracking loss detected, nothing fused, tracking resumes), the outputs, and the real
// TUM freiburg1_rpy frames.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "io/synthetic_source.hpp"
#include "recon/refine/refine.hpp"
#include "tracker_test_util.hpp"

using namespace seamless;

namespace {

TrackSequenceParams default_params(TrackingMode mode) {
  TrackSequenceParams p;
  p.tracker.mode = mode;
  // 1 cm voxels: frame-to-model on the CPU stays within seconds a frame for CI; the model is only
  // the tracking reference here (the 5 mm default is for the reconstruction itself).
  p.volume.voxel_size = 0.01f;
  p.volume.truncation = 0.04f;
  p.volume.hash_buckets = 1 << 16;
  p.volume.capacity = 1 << 15;
  return p;
}

int count_lines(const std::string& path) {
  std::ifstream in(path);
  int n = 0;
  for (std::string line; std::getline(in, line);)
    if (!line.empty() && line[0] != '#') ++n;
  return n;
}

// Frames [from, to) of the synthetic room replaced by views of the same room from the same place
// with the camera turned 100 degrees about its vertical axis (towards another wall): a camera
// swung away for a moment, far outside what ICP can bridge. Ground truth keeps the real path.
class CutSource : public FrameSource {
 public:
  CutSource(const InputParams& in, std::int64_t from, std::int64_t to) : src_(in), from_(from), to_(to) {}
  bool next(RgbdFrame& f) override {
    if (!src_.next(f)) return false;
    if (f.index >= from_ && f.index < to_) {
      const float c = std::cos(1.745f), s = std::sin(1.745f);
      SE3 turn = SE3::identity();
      turn.R = {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
      src_.render(*f.ground_truth * turn, static_cast<std::uint32_t>(f.index), f.depth, f.rgb);
    }
    return true;
  }
  std::optional<std::int64_t> size() const override { return src_.size(); }
  std::string name() const override { return "cut"; }
  Intrinsics intrinsics() const override { return src_.intrinsics(); }

 private:
  SyntheticSource src_;
  std::int64_t from_, to_;
};

}  // namespace

TEST(TrackSequence, SyntheticRoomFrameToModelWithinOneCentimetre) {
  // The synthetic room with Kinect v1 noise, our ICP, ATE RMSE at most 1 cm and no lost
  // frame. 60 frames = 2 s of hand-held orbit (30 deg around the desk).
  InputParams in = test::synthetic_input(60);
  auto src = make_source(in);
  test::TmpOut out("synth");
  auto t = test::track_with_gt(*src, default_params(TrackingMode::frame_to_model), Device::CPU, out.str());
  EXPECT_EQ(t.result.lost_frames, 0);
  ASSERT_EQ(t.result.trajectory.size(), 60u);
  AteResult ate = compute_ate(t.result.trajectory, t.gt);
  EXPECT_LE(ate.trans.rmse, 0.01);
  // The outputs: one trajectory line and one stats row per frame.
  EXPECT_EQ(count_lines(out.str() + "/trajectory.txt"), 60);
  EXPECT_EQ(count_lines(out.str() + "/tracking_stats.csv"), 61);  // + header
  Trajectory back = read_tum_trajectory(out.str() + "/trajectory.txt");
  EXPECT_NEAR(back.back().t[0], t.result.trajectory.back().t[0], 1e-5);
  RecordProperty("ate_rmse_m", std::to_string(ate.trans.rmse));
  // The stage times are consecutive intervals of one timeline, so they add up to the frame's time
  // (to the 0.5 us resolution of a CUDA event per interval; exactly on the CPU's clock). The first
  // frame is not tracked (its gravity and world setup are in no stage); every other one is tracked
  // and fused here, which takes time.
  for (const FrameRecord& r : t.result.frames) {
    double stages = r.preprocess_ms + r.track_ms + r.fuse_ms;
    EXPECT_GT(r.preprocess_ms, 0.0);
    EXPECT_GT(r.fuse_ms, 0.0);
    if (r.frame == 0) {
      EXPECT_EQ(r.track_ms, 0.0);
      EXPECT_LE(stages, r.frame_ms + 2e-3);
    } else {
      EXPECT_GT(r.track_ms, 0.0);
      EXPECT_NEAR(stages, r.frame_ms, 2e-3) << "frame " << r.frame;
    }
  }
}

TEST(TrackSequence, SyntheticRoomFrameToFrameTracksEveryFrame) {
  // Frame-to-frame ICP drifts (each frame's error is kept, nothing averages the noise), so the
  // issue's 1 cm ATE is for frame-to-model (above). Here: every frame tracked, and each frame's
  // motion right to 5 mm (RPE over one frame): the sensor model's depth noise at 2 m is about 1 cm
  // per pixel, and a pose fitted to 10^5 correspondences averages it far below that.
  InputParams in = test::synthetic_input(30);
  auto src = make_source(in);
  TrackSequenceParams p = default_params(TrackingMode::frame_to_frame);
  p.write_files = false;
  auto t = test::track_with_gt(*src, p, Device::CPU, "");
  EXPECT_EQ(t.result.lost_frames, 0);
  RpeResult rpe = compute_rpe(t.result.trajectory, t.gt, 1, "frames");
  EXPECT_LE(rpe.trans.rmse, 0.005);
  RecordProperty("rpe_frame_rmse_m", std::to_string(rpe.trans.rmse));
}

TEST(TrackSequence, CutIsDetectedNotFusedAndTrackingResumes) {
  // Frames 20..24 look 100 degrees away (see CutSource): they must be reported as lost and not
  // fused, and frames 25.. must track again against the last good view (the camera moved 2.5 deg
  // along its path meanwhile), so the trajectory of the real frames stays within 1 cm.
  CutSource src(test::synthetic_input(40), 20, 25);
  TrackSequenceParams p = default_params(TrackingMode::frame_to_model);
  p.write_files = false;
  auto t = test::track_with_gt(src, p, Device::CPU, "");
  EXPECT_EQ(t.result.lost_frames, 5);
  for (const FrameRecord& r : t.result.frames) {
    bool cut = r.frame >= 20 && r.frame < 25;
    EXPECT_EQ(r.result.ok(), !cut) << "frame " << r.frame << ": " << to_string(r.result.status);
    EXPECT_EQ(r.fused, !cut) << "frame " << r.frame;
  }
  Trajectory est, gt;
  for (std::size_t i = 0; i < t.result.frames.size(); ++i)
    if (t.result.frames[i].result.ok()) est.push_back(t.result.trajectory[i]), gt.push_back(t.gt[i]);
  EXPECT_LE(compute_ate(est, gt).trans.rmse, 0.01);
}

// tracker.kind trajectory: the poses of a TUM file, each frame's found by its timestamp. Fusing
// the ground-truth tracker's own trajectory.txt gives the ground-truth tracker's mesh (up to the
// file's 7 decimals, below); a frame missing from the file is
// reported lost and not fused, unless its neighbours are within trajectory_max_gap (then it is
// interpolated); poses given in memory (frame_poses) go to the frames in order.
TEST(TrackSequence, TrajectoryTrackerFusesTheGivenPoses) {
  constexpr int kFrames = 6;
  InputParams in = test::synthetic_input(kFrames, false);
  TrackSequenceParams p = default_params(TrackingMode::frame_to_frame);
  p.tracker.kind = "ground_truth";
  test::TmpOut out("given");
  auto gt_volume = make_volume(p.volume, Device::CPU);
  TrackSequenceResult gt = track_sequence(*make_source(in), p, Device::CPU, out.str(), gt_volume.get());
  ASSERT_EQ(gt.lost_frames, 0);

  TrackSequenceParams t = p;
  t.tracker.kind = "trajectory";
  t.tracker.trajectory = out.str() + "/trajectory.txt";
  t.write_files = false;
  auto volume = make_volume(t.volume, Device::CPU);
  TrackSequenceResult given = track_sequence(*make_source(in), t, Device::CPU, "", volume.get());
  ASSERT_EQ(given.lost_frames, 0);
  const Trajectory file = read_tum_trajectory(t.tracker.trajectory);
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_TRUE(given.frames[k].fused) << k;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(given.trajectory[k].t[i], file[k].t[i], 1e-6) << k;
  }
  // The file's 7 decimals move a pose by 0.1 um: a voxel whose TSDF sits that close to zero may
  // gain or lose its vertex (2 of 108,767 here), so the count agrees to 1e-4 and the bounds to 10 um.
  const Mesh a = gt_volume->extract_mesh(), b = volume->extract_mesh();
  ASSERT_GT(a.positions.size(), 1000u);
  EXPECT_LE(std::abs(static_cast<double>(a.positions.size()) - static_cast<double>(b.positions.size())),
            1e-4 * static_cast<double>(a.positions.size()));
  vec3 lo_a{1e9f, 1e9f, 1e9f}, hi_a = -lo_a, lo_b = lo_a, hi_b = hi_a;
  for (vec3 v : a.positions) lo_a = vmin(lo_a, v), hi_a = vmax(hi_a, v);
  for (vec3 v : b.positions) lo_b = vmin(lo_b, v), hi_b = vmax(hi_b, v);
  EXPECT_LE(length(lo_a - lo_b), 1e-5f);
  EXPECT_LE(length(hi_a - hi_b), 1e-5f);

  // Frames 2 and 4 left out of the file: their neighbours are 67 ms apart (30 frames a second).
  Trajectory some;
  for (int k = 0; k < kFrames; ++k)
    if (k != 2 && k != 4) some.push_back(gt.trajectory[k]);
  t.tracker.trajectory = out.str() + "/some.txt";
  write_tum_trajectory(t.tracker.trajectory, some);
  t.tracker.trajectory_max_gap = 0.05;  // below the 67 ms around frames 2 and 4: both lost
  TrackSequenceResult gaps = track_sequence(*make_source(in), t, Device::CPU, "", nullptr);
  EXPECT_EQ(gaps.lost_frames, 2);
  for (const FrameRecord& r : gaps.frames)
    EXPECT_EQ(r.result.status == TrackStatus::no_reference, r.frame == 2 || r.frame == 4) << r.frame;
  t.tracker.trajectory_max_gap = 0.1;  // interpolated between the neighbours
  TrackSequenceResult filled = track_sequence(*make_source(in), t, Device::CPU, "", nullptr);
  EXPECT_EQ(filled.lost_frames, 0);
  // The synthetic camera moves smoothly: the interpolated pose is within a millimetre of the truth.
  for (int k : {2, 4})
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(filled.trajectory[k].t[i], gt.trajectory[k].t[i], 1e-3) << k;

  // In memory, by order: frame 1 has no pose and is not fused; the others take theirs exactly.
  auto list = std::make_shared<std::vector<std::optional<SE3>>>();
  for (int k = 0; k < kFrames; ++k) list->push_back(k == 1 ? std::nullopt : std::optional<SE3>(gt.trajectory[k].se3()));
  t.frame_poses = list;
  t.tracker.trajectory.clear();
  TrackSequenceResult ordered = track_sequence(*make_source(in), t, Device::CPU, "", nullptr);
  EXPECT_EQ(ordered.lost_frames, 1);
  for (int k = 0; k < kFrames; ++k) {
    EXPECT_EQ(ordered.frames[k].result.ok(), k != 1) << k;
    if (k != 1) {
      EXPECT_EQ(ordered.trajectory[k].se3().t.x, (*list)[k]->t.x) << k;
    }
  }

  // A trajectory kind without a file is a configuration error naming the key.
  TrackerParams bad;
  bad.kind = "trajectory";
  try {
    bad.validate();
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("tracker.trajectory"), std::string::npos) << e.what();
  }
}

TEST(TrackSequence, UnavailableTrackerSaysSo) {
  InputParams in = test::synthetic_input(2);
  auto src = make_source(in);
  TrackSequenceParams p;
  for (const TrackerInfo& t : tracker_registry())
    if (!t.available) p.tracker.kind = t.kind;
  if (p.tracker.kind == "icp") GTEST_SKIP() << "every tracker of the registry is in this build";
  p.write_files = false;
  try {
    track_sequence(*src, p, Device::CPU, "");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not available in this build"), std::string::npos) << e.what();
  }
}

// The tracker section of configs/tum_fr1.yaml before online refinement (it is frame to frame now: see
// docs/TRACKING.md and ctest compare_trackers_fr1_rpy): RGB-D frame-to-model with robust self-balancing
// weights, the Kinect's depth-squared noise, a colour row for every visible pixel and the last frame's image as the
// photometric reference, a constant-velocity prediction, photometric weight 1. Volume at 1 cm (see default_params).
TrackSequenceParams best_tum_params() {
  TrackSequenceParams p = default_params(TrackingMode::frame_to_model);
  p.tracker.kind = "rgbd";
  p.tracker.photometric_weight = 1.f;
  p.tracker.weighting = RgbdWeighting::robust;
  p.tracker.depth_noise = DepthNoiseModel::depth_squared;
  p.tracker.photometric_pixels = PhotometricPixels::visible;
  p.tracker.photometric_reference = PhotometricReference::frame;
  p.tracker.constant_velocity = true;
  p.write_files = false;
  return p;
}

// Real Kinect v1 frames with fast roll/pitch/yaw: the folder's last 75 frames (75-149), which hold its
// fastest turn (6 deg between two frames, around frame 110); every one must be tracked (none reported
// lost). One tracking run serves both checks (the whole folder took over 3 minutes on 2 CPU cores, these
// frames half that): every frame tracked, then, where Ceres is built, the refined trajectory within 3 cm
// (the tracker's ATE RMSE goal). The tracker alone measures 2.5 cm at 5 mm on the whole folder (with
// robust weights, depth-squared noise, colour on every visible pixel; 3.3 cm before them; frame-to-frame
// RGB-D 3.1 cm, geometric ICP much worse: on these frames the Kinect depth shows about 25 % less rotation
// between frames than the ground truth and the colour do, see docs/TRACKING.md). Our best tracker is
// therefore the tracker followed by the Ceres refinement (the refine section of configs/tum_fr1.yaml: a
// keyframe every 5 frames, so that consecutive keyframes of this fast rotation stay within the 30 degrees
// a pair may differ; docs/TRACKING.md, "Ceres refinement", has the sensitivity to the keyframe spacing).
// Needs Ceres (libceres-dev).
TEST(TrackSequence, TumFreiburg1RpyBestTrackerTracksEveryFrameAndRefinesWithinThreeCentimetres) {
  const std::string dir = test::tum_rpy_dir();
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " is absent (shared test data)";
  InputParams in = test::tum_input(dir);
  in.first_frame = 75;
  auto src = make_source(in);
  TrackSequenceParams p = best_tum_params();
  auto t = test::track_with_gt(*src, p, Device::CPU, "");
  EXPECT_EQ(t.result.lost_frames, 0);
  ASSERT_EQ(t.result.trajectory.size(), 75u);
  const Trajectory gt = read_tum_trajectory(dir + "/groundtruth.txt");
  const AteResult odometry = compute_ate(t.result.trajectory, gt);
  RecordProperty("ate_odometry_m", std::to_string(odometry.trans.rmse));
  if (!refine_available()) GTEST_SKIP() << "this build has no Ceres (libceres-dev): the refinement is not built";
  std::vector<bool> tracked;
  for (const FrameRecord& f : t.result.frames) tracked.push_back(f.result.ok());
  RefineParams refine;
  refine.enabled = true;
  refine.keyframe_every = 5;
  refine.weighting = RgbdWeighting::robust;
  refine.depth_noise = DepthNoiseModel::depth_squared;
  refine.photometric_pixels = PhotometricPixels::visible;
  auto again = make_source(in);
  RefineResult r = refine_trajectory(*again, t.result.trajectory, refine, p.preprocess, Device::CPU, tracked);
  const AteResult refined = compute_ate(r.trajectory, gt);
  EXPECT_LE(refined.trans.rmse, 0.03) << "odometry alone " << odometry.trans.rmse;
  RecordProperty("ate_refined_m", std::to_string(refined.trans.rmse));
}
