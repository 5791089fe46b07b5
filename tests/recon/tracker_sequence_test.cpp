// Whole tracked sequences against ground truth: the synthetic room (noisy Kinect model), a cut in
// the sequence (tracking loss detected, nothing fused, tracking resumes), the outputs, and the real
// TUM freiburg1_rpy frames.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "io/synthetic_source.hpp"
#include "core/error.hpp"
#include "tracker_test_util.hpp"

using namespace seamless;

namespace {

TrackSequenceParams default_params(const std::string& mode) {
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

// Frames [from, to) of `main` replaced by the same-numbered frames of `other` (another place):
// a camera that was carried elsewhere for a moment, or a source that glitched.
class CutSource : public FrameSource {
 public:
  CutSource(std::unique_ptr<FrameSource> main, std::unique_ptr<FrameSource> other, std::int64_t from, std::int64_t to)
      : main_(std::move(main)), other_(std::move(other)), from_(from), to_(to) {}
  bool next(RgbdFrame& f) override {
    if (!main_->next(f)) return false;
    RgbdFrame o;
    if (!other_->next(o)) return true;
    if (f.index >= from_ && f.index < to_) {
      f.depth = std::move(o.depth);
      f.rgb = std::move(o.rgb);
      f.accelerometer = o.accelerometer;
    }
    return true;
  }
  std::optional<std::int64_t> size() const override { return main_->size(); }
  std::string name() const override { return "cut"; }
  Intrinsics intrinsics() const override { return main_->intrinsics(); }

 private:
  std::unique_ptr<FrameSource> main_, other_;
  std::int64_t from_, to_;
};

}  // namespace

TEST(TrackSequence, SyntheticRoomFrameToModelWithinOneCentimetre) {
  // Issue 5: the synthetic room with Kinect v1 noise, our ICP, ATE RMSE at most 1 cm and no lost
  // frame. 60 frames = 2 s of hand-held orbit (30 deg around the desk).
  InputParams in = test::synthetic_input(60);
  auto src = make_source(in);
  test::TmpOut out("synth");
  auto t = test::track_with_gt(*src, default_params("frame_to_model"), Device::CPU, out.str());
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
}

TEST(TrackSequence, SyntheticRoomFrameToFrameWithinOneCentimetre) {
  // Frame-to-frame ICP drifts (each frame's error is kept, nothing averages the noise), so the
  // issue's 1 cm is asked of it over 1 s of motion only.
  InputParams in = test::synthetic_input(30);
  auto src = make_source(in);
  TrackSequenceParams p = default_params("frame_to_frame");
  p.write_files = false;
  auto t = test::track_with_gt(*src, p, Device::CPU, "");
  EXPECT_EQ(t.result.lost_frames, 0);
  EXPECT_LE(compute_ate(t.result.trajectory, t.gt).trans.rmse, 0.01);
}

TEST(TrackSequence, CutIsDetectedNotFusedAndTrackingResumes) {
  // Frames 20..24 come from the other side of the room (orbit start 180 deg away): they must be
  // reported as lost and not fused, and frames 25.. must track again against the last good view
  // (the camera moved 2.5 deg meanwhile), so the trajectory of the real frames stays within 1 cm.
  InputParams in = test::synthetic_input(40);
  InputParams elsewhere = in;
  elsewhere.synthetic.start_deg += 180.f;
  CutSource src(make_source(in), make_source(elsewhere), 20, 25);
  TrackSequenceParams p = default_params("frame_to_model");
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

TEST(TrackSequence, UnavailableTrackerSaysSo) {
  InputParams in = test::synthetic_input(2);
  auto src = make_source(in);
  TrackSequenceParams p;
  p.tracker.kind = "opencv_rgbd";
  p.write_files = false;
  try {
    track_sequence(*src, p, Device::CPU, "");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not available in this build"), std::string::npos) << e.what();
  }
}

TEST(TrackSequence, TumFreiburg1RpyBestTrackerWithinThreeCentimetres) {
  // Issue 5: real Kinect v1 frames with fast roll/pitch/yaw; our best tracker (the configuration of
  // configs/tum_fr1.yaml: ICP frame-to-model) must track every frame with ATE RMSE <= 3 cm.
  const std::string dir = test::tum_rpy_dir();
  if (!std::filesystem::exists(dir)) GTEST_SKIP() << dir << " is absent (shared test data)";
  auto src = make_source(test::tum_input(dir));
  TrackSequenceParams p = default_params("frame_to_model");
  p.write_files = false;
  auto t = test::track_with_gt(*src, p, Device::CPU, "");
  EXPECT_EQ(t.result.lost_frames, 0);
  ASSERT_EQ(t.result.trajectory.size(), 150u);
  Trajectory gt = read_tum_trajectory(dir + "/groundtruth.txt");
  AteResult ate = compute_ate(t.result.trajectory, gt);
  EXPECT_LE(ate.trans.rmse, 0.03);
  RecordProperty("ate_rmse_m", std::to_string(ate.trans.rmse));
}
