// ATE / RPE against cases whose answer is known by construction.
#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"
#include "eval/trajectory_eval.hpp"

using namespace seamless;

namespace {

TumPose pose(double t, double x, double y, double z, double yaw = 0) {
  TumPose p;
  p.timestamp = t;
  p.t[0] = x;
  p.t[1] = y;
  p.t[2] = z;
  p.q[2] = std::sin(yaw / 2);
  p.q[3] = std::cos(yaw / 2);  // rotation about z
  return p;
}

// A curved 3-D path at 30 Hz with a changing orientation.
Trajectory wiggle(int n) {
  Trajectory tr;
  for (int i = 0; i < n; ++i) {
    double t = 100.0 + i / 30.0;
    tr.push_back(pose(t, std::sin(t), 0.3 * std::cos(2 * t), 0.1 * t, 0.5 * std::sin(t)));
  }
  return tr;
}

TEST(Ate, RigidlyMovedCopyHasZeroError) {
  Trajectory gt = wiggle(200);
  // est = M * gt for a rigid M: alignment recovers M^-1, so ATE vanishes (double rounding only).
  SE3 M{};
  const float a = 0.7f;
  M.R = {{{std::cos(a), -std::sin(a), 0}, {std::sin(a), std::cos(a), 0}, {0, 0, 1}}};
  M.t = {1.f, -2.f, 0.5f};
  Trajectory est;
  for (const TumPose& p : gt) {
    SE3 moved = M * p.se3();
    est.push_back(TumPose::from_se3(p.timestamp, moved));
  }
  AteResult r = compute_ate(est, gt);
  EXPECT_EQ(r.trans.count, 200u);
  // from_se3 goes through float (SE3 is float): positions of ~5 m carry ~5e-7 m rounding.
  EXPECT_LT(r.trans.rmse, 2e-6);
}

TEST(Ate, KnownOffsetOfOnePoseGivesKnownError) {
  // Four corners of a square plus its centre; moving only the centre by d along z cannot be
  // aligned away entirely. The optimal alignment shifts everything by d/5 along z: the centre's
  // error is 4d/5 and each corner's d/5. RMSE = d * sqrt((16 + 4) / 25 / 5) = d * 0.4.
  Trajectory gt = {pose(0, 0, 0, 0), pose(1, 1, 0, 0), pose(2, 1, 1, 0), pose(3, 0, 1, 0), pose(4, 0.5, 0.5, 0)};
  Trajectory est = gt;
  const double d = 0.1;
  est[4].t[2] += d;
  AteResult r = compute_ate(est, gt);
  EXPECT_NEAR(r.trans.rmse, 0.4 * d, 1e-9);
  EXPECT_NEAR(r.trans.max, 0.8 * d, 1e-9);
}

TEST(Rpe, ScaleDriftGivesKnownTranslationError) {
  // Straight line at 1 m/s; the estimate moves 2% too far each frame. Per frame the relative
  // error is 0.02 * (1/30) m; per second 0.02 * 1 m.
  Trajectory gt, est;
  for (int i = 0; i < 90; ++i) {
    double t = i / 30.0;
    gt.push_back(pose(t, t, 0, 0));
    est.push_back(pose(t, 1.02 * t, 0, 0));
  }
  RpeResult f = compute_rpe(est, gt, 1, "frames");
  EXPECT_EQ(f.trans.count, 89u);
  EXPECT_NEAR(f.trans.rmse, 0.02 / 30, 1e-12);
  EXPECT_NEAR(f.rot.max, 0.0, 1e-9);
  RpeResult s = compute_rpe(est, gt, 1.0, "seconds");
  EXPECT_NEAR(s.trans.median, 0.02, 1e-9);
}

TEST(Rpe, RotationDriftGivesKnownAngle) {
  // The estimate yaws 0.1 degree per frame more than the truth (which does not rotate).
  Trajectory gt, est;
  const double step = 0.1 * M_PI / 180;
  for (int i = 0; i < 60; ++i) {
    gt.push_back(pose(i / 30.0, 0, 0, 0));
    est.push_back(pose(i / 30.0, 0, 0, 0, i * step));
  }
  RpeResult r = compute_rpe(est, gt, 1, "frames");
  EXPECT_NEAR(r.rot.mean, 0.1, 1e-6);
  EXPECT_NEAR(r.trans.max, 0.0, 1e-12);
}

TEST(Associate, MatchesWithinToleranceOnly) {
  Trajectory gt = {pose(1.00, 0, 0, 0), pose(1.10, 0, 0, 0), pose(1.20, 0, 0, 0)};
  Trajectory est = {pose(1.01, 0, 0, 0), pose(1.13, 0, 0, 0), pose(1.195, 0, 0, 0)};
  auto p = associate(est, gt, 0.02);
  ASSERT_EQ(p.size(), 2u);  // 1.13 is 0.03 from 1.10: left out
  EXPECT_EQ(p[0], std::make_pair(std::size_t{0}, std::size_t{0}));
  EXPECT_EQ(p[1], std::make_pair(std::size_t{2}, std::size_t{2}));
  EXPECT_THROW(compute_ate(est, gt), Error);  // only 2 pairs
}

TEST(Ate, Sim3RecoversTheScaleOfAScaledCopy) {
  // est = (1/s) * (rotated, moved gt): a monocular estimate in the wrong unit. Sim(3) alignment
  // recovers s and leaves no error (double rounding only); SE(3) cannot absorb the scale.
  Trajectory gt = wiggle(200), est;
  const double s = 1.25, c = std::cos(0.3), sn = std::sin(0.3);
  for (const TumPose& p : gt) {
    TumPose e = p;
    e.t[0] = (c * p.t[0] - sn * p.t[1] + 0.5) / s;
    e.t[1] = (sn * p.t[0] + c * p.t[1] - 1.0) / s;
    e.t[2] = (p.t[2] + 2.0) / s;
    est.push_back(e);
  }
  EvalOptions o;
  o.align = Alignment::sim3;
  AteResult r = compute_ate(est, gt, o);
  EXPECT_NEAR(r.scale, s, 1e-9);
  EXPECT_LT(r.trans.rmse, 1e-9);
  o.align = Alignment::se3;
  EXPECT_GT(compute_ate(est, gt, o).trans.rmse, 0.05);  // the path spans metres: 20% off is centimetres at least
  EXPECT_EQ(compute_ate(est, gt, o).scale, 1.0);
}

TEST(Ate, NoAlignmentKeepsAConstantOffset) {
  // Every estimated position 3 cm, 4 cm off (5 cm): without alignment every error is 5 cm; the
  // rigid alignment takes the offset away entirely.
  Trajectory gt = wiggle(100), est = gt;
  for (TumPose& p : est) p.t[0] += 0.03, p.t[2] -= 0.04;
  EvalOptions o;
  o.align = Alignment::none;
  AteResult r = compute_ate(est, gt, o);
  EXPECT_NEAR(r.trans.rmse, 0.05, 1e-12);
  EXPECT_NEAR(r.trans.min, 0.05, 1e-12);
  EXPECT_NEAR(r.aligned[7].t[0], est[7].t[0], 0.0);  // not moved
  o.align = Alignment::se3;
  EXPECT_LT(compute_ate(est, gt, o).trans.rmse, 1e-9);
  EXPECT_THROW(parse_alignment("affine"), Error);
}

TEST(Associate, OffsetIsAddedToTheEstimatesTimestamps) {
  // The estimate's clock runs 0.5 s ahead: with offset -0.5 every pose meets its ground truth.
  Trajectory gt = wiggle(60), est = gt;
  for (TumPose& p : est) p.timestamp += 0.5;
  EvalOptions o;
  EXPECT_EQ(associate(est, gt, o.t_max_diff, -0.5).size(), 60u);
  o.offset = -0.5;
  AteResult r = compute_ate(est, gt, o);
  EXPECT_EQ(r.trans.count, 60u);
  EXPECT_LT(r.trans.rmse, 1e-9);
  // Without it the poses pair with those 15 frames later (0.5 s at 30 Hz): a wrong answer, not 0.
  EXPECT_GT(compute_ate(est, gt).trans.rmse, 0.01);
}

TEST(Associate, TMaxDiffBoundsThePairs) {
  // Estimates 15 ms after each ground-truth sample: TUM's 0.02 s pairs them all, evo's 0.01 none.
  Trajectory gt = wiggle(30), est = gt;
  for (TumPose& p : est) p.timestamp += 0.015;
  EXPECT_EQ(associate(est, gt, 0.02).size(), 30u);
  EXPECT_TRUE(associate(est, gt, 0.01).empty());
  EvalOptions o;
  o.t_max_diff = 0.01;
  EXPECT_THROW(compute_ate(est, gt, o), Error);
}

TEST(Rpe, OneSecondFollowsTumsPairing) {
  // 90 poses at 30 Hz, 1 m/s along x, the estimate 2% too fast. TUM's evaluate_rpe.py pairs each
  // pose i with the pose closest to t_i + 1 s (i + 30) unless that is the last pose (89): i = 0..58,
  // 59 pairs, each 2 cm off over its second: 0.02 m/s.
  Trajectory gt, est;
  for (int i = 0; i < 90; ++i) {
    double t = 1000.0 + i / 30.0;
    gt.push_back(pose(t, i / 30.0, 0, 0));
    est.push_back(pose(t, 1.02 * i / 30.0, 0, 0));
  }
  RpeResult s = compute_rpe(est, gt, 1.0, "seconds", EvalOptions{});
  EXPECT_EQ(s.trans.count, 59u);
  EXPECT_NEAR(s.trans.rmse, 0.02, 1e-9);
  EXPECT_NEAR(s.trans.max, 0.02, 1e-9);
  EXPECT_NEAR(s.rot.max, 0.0, 1e-9);
  // Sim(3) takes the 2% away (evo_rpe -as): the scaled estimate moves exactly like the truth.
  EvalOptions o;
  o.align = Alignment::sim3;
  EXPECT_LT(compute_rpe(est, gt, 1.0, "seconds", o).trans.max, 1e-9);
  // Per frame every pair (i, i+1) counts, the last one included (evo's pairing): 89 pairs.
  EXPECT_EQ(compute_rpe(est, gt, 1, "frames", EvalOptions{}).trans.count, 89u);
}

TEST(Rpe, SmallRotationAnglesKeepTheirDigits) {
  // 1e-6 degree of yaw per frame: acos of the trace alone would return 0 or ~1e-6 +- 100%.
  Trajectory gt, est;
  const double step = 1e-6 * M_PI / 180;
  for (int i = 0; i < 10; ++i) {
    gt.push_back(pose(i / 30.0, 0, 0, 0));
    est.push_back(pose(i / 30.0, 0, 0, 0, i * step));
  }
  EXPECT_NEAR(compute_rpe(est, gt, 1, "frames").rot.mean, 1e-6, 1e-12);
}

}  // namespace
