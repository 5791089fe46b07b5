// The Ceres refinement (src/recon/refine) against ground truth on the synthetic room (Kinect v1
// noise model): injected drift is removed, a consistent trajectory stays where it is, and bad input
// is a no-op with a reason or a clear error. Skips when the build has no Ceres.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "core/error.hpp"
#include "eval/trajectory_eval.hpp"
#include "io/synthetic_source.hpp"
#include "recon/refine/online_refine.hpp"
#include "recon/refine/refine.hpp"
#include "tracker_test_util.hpp"

using namespace seamless;

namespace {

constexpr double kDegToRad = 3.14159265358979323846 / 180.0;
constexpr int kFrames = 60;  // 2 s of the hand-held orbit: 30 degrees around the desk

// The synthetic sequence's first `frames` frames, rendered once per test process (rendering is the
// slow part on a CPU: ctest runs each case in a process of its own, so a case that needs 30 frames
// renders 30, not the whole sequence) and replayed: the refinement reads its source from the start,
// like `seamless track` does.
const std::vector<RgbdFrame>& rendered(int frames = kFrames) {
  static const std::unique_ptr<FrameSource> src = make_source(test::synthetic_input(kFrames));
  static std::vector<RgbdFrame> v;
  RgbdFrame f;
  while (std::ssize(v) < frames && src->next(f)) {
    RgbdFrame c;
    c.index = f.index, c.timestamp = f.timestamp, c.intrinsics = f.intrinsics;
    c.depth = f.depth.clone(Device::CPU), c.rgb = f.rgb.clone(Device::CPU);
    c.accelerometer = f.accelerometer, c.ground_truth = f.ground_truth;
    v.push_back(std::move(c));
  }
  return v;
}

class ReplaySource : public FrameSource {
 public:
  explicit ReplaySource(int frames) : n_(frames) { rendered(frames); }
  bool next(RgbdFrame& f) override {
    if (i_ >= n_) return false;
    const RgbdFrame& s = rendered(n_).at(i_++);
    f.index = s.index, f.timestamp = s.timestamp, f.intrinsics = s.intrinsics;
    f.depth = s.depth.clone(Device::CPU), f.rgb = s.rgb.clone(Device::CPU);
    f.accelerometer = s.accelerometer, f.ground_truth = s.ground_truth;
    return true;
  }
  std::optional<std::int64_t> size() const override { return n_; }
  std::string name() const override { return "replayed synthetic room"; }
  Intrinsics intrinsics() const override { return make_source(test::synthetic_input(1))->intrinsics(); }

 private:
  int n_, i_ = 0;
};

// The ground-truth poses of the synthetic sequence (what the frames were rendered from).
Trajectory ground_truth(int frames) {
  Trajectory gt;
  const std::vector<RgbdFrame>& r = rendered(frames);
  for (int i = 0; i < frames; ++i) gt.push_back(TumPose::from_se3(r[i].timestamp, *r[i].ground_truth));
  return gt;
}

SE3 yaw(double deg) {
  const float c = static_cast<float>(std::cos(deg * kDegToRad)), s = static_cast<float>(std::sin(deg * kDegToRad));
  SE3 T = SE3::identity();
  T.R = {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
  return T;
}

// Drift like an odometry's: every frame adds the same small error to the relative motion, so the
// pose error grows linearly: 0.05 deg of yaw and 0.5 mm sideways per frame, 3 deg and 3 cm at the
// end of the sequence (frame-to-frame ICP on real data drifts this much and more).
Trajectory with_drift(const Trajectory& gt) {
  Trajectory out;
  for (std::size_t f = 0; f < gt.size(); ++f) {
    SE3 err = yaw(0.05 * f);
    err.t = {0.0005f * f, 0.f, 0.f};
    out.push_back(TumPose::from_se3(gt[f].timestamp, gt[f].se3() * err));
  }
  return out;
}

RefineParams params() {
  RefineParams p;
  p.enabled = true;
  p.keyframe_every = 10;
  return p;
}

RefineResult refine(const Trajectory& input, const RefineParams& p, int frames = kFrames) {
  ReplaySource src(frames);
  return refine_trajectory(src, input, p, PreprocessParams{}, Device::CPU);
}

double position_change(const TumPose& a, const TumPose& b) {
  return std::sqrt(std::pow(a.t[0] - b.t[0], 2) + std::pow(a.t[1] - b.t[1], 2) + std::pow(a.t[2] - b.t[2], 2));
}

#define REQUIRE_CERES() \
  if (!refine_available()) GTEST_SKIP() << "this build has no Ceres (libceres-dev): the refinement is not built"

}  // namespace

TEST(Refine, KeyframesEveryNFramesAndByMotion) {
  Trajectory gt = ground_truth(kFrames);
  RefineParams p = params();
  std::vector<std::int64_t> kf = select_keyframes(gt, p);
  // 0, 10, ..., 50 and the last frame (59 is 9 >= 10/2 frames after 50).
  EXPECT_EQ(kf, (std::vector<std::int64_t>{0, 10, 20, 30, 40, 50, 59}));
  // A lost frame is never a keyframe (its pose is the last good one, not its own).
  std::vector<bool> tracked(gt.size(), true);
  tracked[10] = false;
  kf = select_keyframes(gt, p, tracked);
  EXPECT_EQ(kf[1], 11);
  // By motion: the orbit turns 0.5 deg a frame, so a 2.5-degree threshold takes about every 5th.
  p.keyframes = KeyframeRule::motion;
  p.keyframe_rotation_deg = 2.5f;
  p.keyframe_translation = 10.f;
  kf = select_keyframes(gt, p);
  EXPECT_GE(kf.size(), 10u);
  EXPECT_LE(kf.size(), 14u);
}

TEST(Refine, InjectedDriftIsRemoved) {
  REQUIRE_CERES();
  Trajectory gt = ground_truth(kFrames);
  Trajectory drifted = with_drift(gt);
  RefineResult r = refine(drifted, params());
  ASSERT_EQ(r.trajectory.size(), gt.size());
  EXPECT_GT(r.stats.pair_edges, r.stats.keyframes - 1);  // loop edges beyond the chain
  const double before = compute_ate(drifted, gt).trans.rmse;
  const double after = compute_ate(r.trajectory, gt).trans.rmse;
  // Bound: what is left after refinement is the pairwise alignments' own error. Frame-to-frame ICP
  // on this sensor model is right to 5 mm per frame pair (TrackSequence.SyntheticRoomFrameToFrame*),
  // and the graph averages several such alignments per keyframe, so 5 mm bounds the refined ATE;
  // the injected drift alone is several times that.
  EXPECT_GT(before, 0.008);
  EXPECT_LE(after, 0.005) << "before " << before;
  EXPECT_LE(after, before);
  EXPECT_GT(r.stats.iterations, 0);
  EXPECT_LT(r.stats.final_cost, r.stats.initial_cost);
  RecordProperty("ate_before_m", std::to_string(before));
  RecordProperty("ate_after_m", std::to_string(after));
}

TEST(Refine, ConsistentTrajectoryStays) {
  REQUIRE_CERES();
  Trajectory gt = ground_truth(kFrames);
  RefineResult r = refine(gt, params());
  ASSERT_EQ(r.trajectory.size(), gt.size());
  // Same bound as above: the alignments may disagree with the truth by their own error, 5 mm, and
  // the graph can move a keyframe by no more than that disagreement.
  double worst = 0;
  for (std::size_t f = 0; f < gt.size(); ++f) worst = std::max(worst, position_change(gt[f], r.trajectory[f]));
  EXPECT_LE(worst, 0.005);
  EXPECT_LE(r.stats.max_correction_deg, 0.5);  // 5 mm at 1 m from the camera's view centre is 0.3 deg
  EXPECT_LE(compute_ate(r.trajectory, gt).trans.rmse, 0.003);
}

TEST(Refine, OneFrameIsANoOpWithAReason) {
  Trajectory gt = ground_truth(1);
  RefineResult r = refine(gt, params(), 1);
  ASSERT_EQ(r.trajectory.size(), 1u);
  EXPECT_EQ(r.stats.keyframes, 1);
  EXPECT_NE(r.stats.message.find("fewer than two keyframes"), std::string::npos) << r.stats.message;
  EXPECT_EQ(position_change(r.trajectory[0], gt[0]), 0.0);
}

TEST(Refine, NoOverlappingKeyframesIsANoOpWithAReason) {
  REQUIRE_CERES();
  // The poses say the camera jumped 2 m sideways every frame: no two keyframes can see the same
  // surface from where the trajectory puts them, so no pair is aligned and nothing is moved.
  Trajectory gt = ground_truth(30);
  Trajectory apart = gt;
  for (std::size_t f = 0; f < apart.size(); ++f) apart[f].t[0] += 2.0 * f;
  RefineResult r = refine(apart, params(), 30);
  EXPECT_EQ(r.stats.pair_edges, 0);
  EXPECT_NE(r.stats.message.find("no keyframe pair"), std::string::npos) << r.stats.message;
  for (std::size_t f = 0; f < apart.size(); ++f) EXPECT_EQ(position_change(apart[f], r.trajectory[f]), 0.0);
}

TEST(Refine, TrajectoryLongerThanTheSourceIsAnError) {
  REQUIRE_CERES();
  Trajectory gt = ground_truth(30);
  ReplaySource src(20);
  try {
    refine_trajectory(src, gt, params(), PreprocessParams{}, Device::CPU);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("gave 20 frames but the trajectory has 30"), std::string::npos) << e.what();
  }
}

TEST(Refine, EnabledWithoutCeresNamesThePackage) {
  RefineParams p;
  p.enabled = true;
  if (refine_available()) {
    EXPECT_NO_THROW(require_refine(p));
    return;
  }
  try {
    require_refine(p);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("libceres-dev"), std::string::npos) << e.what();
  }
}

// The online worker (refine.online) on its own: keyframes of the drifted trajectory handed over
// one by one with their images, as the tracking thread does. Nothing is published before the first
// solve; afterwards latest() is the newest graph, and its keyframes carry the known correction
// (ground truth * drifted^-1) that the offline test removes.
TEST(Refine, OnlineWorkerQueueAndLatestSolution) {
  REQUIRE_CERES();
  Trajectory gt = ground_truth(kFrames);
  Trajectory drifted = with_drift(gt);
  RefineParams p = params();
  p.online = true;
  const Intrinsics K = ReplaySource(1).intrinsics();
  OnlineRefiner worker(p, PreprocessParams{}, K);
  EXPECT_EQ(worker.latest(), nullptr);  // no keyframe yet: no solution
  std::vector<double> submit_s;
  for (int f = 0; f < kFrames; f += p.keyframe_every) {
    const RgbdFrame& s = rendered()[f];
    RgbdFrame c;
    c.index = s.index, c.timestamp = s.timestamp, c.intrinsics = s.intrinsics;
    c.depth = s.depth.clone(Device::CPU), c.rgb = s.rgb.clone(Device::CPU);
    const auto t0 = std::chrono::steady_clock::now();
    worker.submit(f, drifted[f].timestamp, drifted[f].se3(), std::move(c));
    submit_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  worker.finish();
  const OnlineRefineStats st = worker.stats();
  const auto kf = static_cast<std::int64_t>((kFrames + p.keyframe_every - 1) / p.keyframe_every);
  EXPECT_EQ(st.keyframes, kf);
  ASSERT_GE(st.solves, 1);
  EXPECT_GT(st.pair_edges, kf - 1);  // loop edges beyond the chain, as offline
  // A handover never includes a solve: the longest one is shorter than the shortest keyframe's
  // background work (pyramid, alignments, Ceres), which is what submit would cost if it waited.
  EXPECT_LT(*std::max_element(submit_s.begin(), submit_s.end()),
            *std::min_element(st.keyframe_s.begin(), st.keyframe_s.end()));
  std::shared_ptr<const OnlineSolution> sol = worker.latest();
  ASSERT_NE(sol, nullptr);
  EXPECT_EQ(sol->version, st.solves);
  ASSERT_EQ(static_cast<std::int64_t>(sol->frames.size()), kf);  // the last solve saw every keyframe
  // The known correction of the newest keyframe: ground truth * drifted^-1 there (3 deg and 2.5 cm
  // at frame 50). Bound as InjectedDriftIsRemoved: 5 mm, the pairwise alignments' own error.
  const std::int64_t last = sol->frames.back();
  const SE3 known = gt[last].se3() * drifted[last].se3().inverse();
  const SE3 got = sol->refined.back() * sol->odometry.back().inverse();
  EXPECT_LT(length((known.inverse() * got).t), 0.005);
  EXPECT_LT(rotation_angle_deg((known.inverse() * got).R), 0.5);
  // Every frame follows the final graph: ATE within the same 5 mm, and better than the drift.
  const Trajectory out = worker.corrected(drifted);
  const double after = compute_ate(out, gt).trans.rmse, before = compute_ate(drifted, gt).trans.rmse;
  EXPECT_LT(after, 0.005);
  EXPECT_LT(after, before);
}
