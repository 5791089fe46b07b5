// seamless's ATE and RPE against evo's on a real trajectory: the ground truth of the shared
// tum_fr1_rpy_000-149 (TUM RGB-D, freiburg1_rpy, CC BY 4.0) and the estimate in
// tests/eval/data/tum_fr1_rpy_000-149_icp.txt (our frame-to-model ICP on those 150 frames, CPU,
// `seamless track configs/tum_fr1.yaml --set tracker.kind=icp --set refine.enabled=false`; it
// drifts to 8 cm ATE, which makes the alignments do real work).
//
// Provenance of the reference numbers: evo 1.38.1 (pip install evo, Python 3.11), stats.json of
//   evo_ape tum GT EST --t_max_diff 0.02 -a  [-as | no alignment]      --save_results ...
//   evo_ape tum GT EST --t_max_diff 0.02 -a --t_offset 0.01            --save_results ...
//   evo_rpe tum GT EST --t_max_diff 0.02 -d 1 -u f -r trans_part [-as] --save_results ...
//   evo_rpe tum GT EST --t_max_diff 0.02 -d 1 -u f -r angle_deg        --save_results ...
// with GT = ../shared/data/tum_fr1_rpy_000-149/groundtruth.txt, EST = the file above; -as printed
// "Scale correction: 0.29311942231251775". tests/eval/evo_crosscheck_test.py reruns evo on the same
// files where it is installed.
// The RPE over 1 s (evo has no time delta): TUM's evaluate_rpe.py (J. Sturm 2013, the benchmark's
// tool; its Python 2 print statements adapted to run it) with
//   GT EST --fixed_delta --delta 1 --delta_unit s [--scale 0.29311942231251775] --verbose
// at full precision (numpy's statistics of its per-pair errors).
#include <gtest/gtest.h>

#include <filesystem>

#include "eval/trajectory_eval.hpp"
#include "seamless/build_config.hpp"

using namespace seamless;

namespace {

// Both sides compute in double from the same 150 pairs; they differ in summation order and in the
// SVD's implementation (Eigen's JacobiSVD against numpy's LAPACK), which moves results by a few
// ulps of the ~1 m coordinates (1e-15 m). 1e-9 m is far above that and far below the 0.1 mm the
// evaluation must agree to.
constexpr double kTol = 1e-9;

struct Files {
  Trajectory gt, est;
};

bool load(Files& f) {
  const std::string gt = std::string(SEAMLESS_TEST_DATA) + "/tum_fr1_rpy_000-149/groundtruth.txt";
  if (!std::filesystem::exists(gt)) return false;
  f.gt = read_tum_trajectory(gt);
  f.est = read_tum_trajectory(std::string(SEAMLESS_SOURCE_DIR) + "/tests/eval/data/tum_fr1_rpy_000-149_icp.txt");
  return true;
}

#define LOAD_OR_SKIP(f) \
  Files f;              \
  if (!load(f)) GTEST_SKIP() << "shared data tum_fr1_rpy_000-149 is absent"

void expect_stats(const ErrorStats& s, double rmse, double mean, double median, double std, double min, double max) {
  EXPECT_NEAR(s.rmse, rmse, kTol);
  EXPECT_NEAR(s.mean, mean, kTol);
  EXPECT_NEAR(s.median, median, kTol);
  EXPECT_NEAR(s.std, std, kTol);
  EXPECT_NEAR(s.min, min, kTol);
  EXPECT_NEAR(s.max, max, kTol);
}

EvalOptions with(Alignment a, double offset = 0) {
  EvalOptions o;
  o.t_max_diff = 0.02;
  o.align = a;
  o.offset = offset;
  return o;
}

}  // namespace

TEST(EvoReference, AteSe3) {
  LOAD_OR_SKIP(f);
  AteResult r = compute_ate(f.est, f.gt, with(Alignment::se3));
  EXPECT_EQ(r.trans.count, 150u);
  expect_stats(r.trans, 0.07952194358521113, 0.060594292241253074, 0.04315354463641986, 0.05149826462465623,
               0.016568132025828023, 0.2240903866448181);
}

TEST(EvoReference, AteSim3) {
  LOAD_OR_SKIP(f);
  AteResult r = compute_ate(f.est, f.gt, with(Alignment::sim3));
  EXPECT_NEAR(r.scale, 0.29311942231251775, kTol);
  expect_stats(r.trans, 0.01700798402554101, 0.01617214238640616, 0.015281636882328618, 0.0052662445107366125,
               0.007150176948530016, 0.03625417271247517);
}

TEST(EvoReference, AteWithoutAlignment) {
  LOAD_OR_SKIP(f);
  AteResult r = compute_ate(f.est, f.gt, with(Alignment::none));
  expect_stats(r.trans, 2.1103735385643203, 2.1101680075307803, 2.0991376247282076, 0.029452542607884224,
               2.0759332812285685, 2.193567516121159);
}

TEST(EvoReference, AteWithTimeOffset) {
  LOAD_OR_SKIP(f);
  AteResult r = compute_ate(f.est, f.gt, with(Alignment::se3, 0.01));
  EXPECT_EQ(r.trans.count, 150u);
  expect_stats(r.trans, 0.07973375415814761, 0.06072438039018432, 0.04337770848714498, 0.051672247661390926,
               0.016506826779185368, 0.22431269535823478);
}

TEST(EvoReference, RpePerFrame) {
  LOAD_OR_SKIP(f);
  RpeResult r = compute_rpe(f.est, f.gt, 1, "frames", with(Alignment::se3));
  EXPECT_EQ(r.trans.count, 149u);
  expect_stats(r.trans, 0.009301277588343601, 0.006238273554214988, 0.0032321481665076508, 0.006899109206137041,
               0.0003997275278435808, 0.048871044802983044);
  expect_stats(r.rot, 0.6971432995627898, 0.5500198126961642, 0.41513905102836984, 0.4283538090959038,
               0.026274798593482588, 2.3254799302699833);
  RpeResult s = compute_rpe(f.est, f.gt, 1, "frames", with(Alignment::sim3));
  expect_stats(s.trans, 0.002663680063527925, 0.0020191368033623362, 0.0015840790691267423, 0.0017373192136575985,
               0.00017844941460221688, 0.012923248674281367);
}

TEST(TumRpeReference, OneSecond) {
  LOAD_OR_SKIP(f);
  RpeResult r = compute_rpe(f.est, f.gt, 1.0, "seconds", with(Alignment::se3));
  EXPECT_EQ(r.trans.count, 119u);
  expect_stats(r.trans, 0.14336711476163944, 0.10994461562748745, 0.06953362670653195, 0.09201255941229503,
               0.010130386220524333, 0.2830814070717319);
  expect_stats(r.rot, 4.3116877057608045, 3.9454825690595667, 3.6713897957035635, 1.7389129274509385,
               0.36234896577615544, 8.204468967584198);
  // --scale with the Sim(3) scale: what `seamless eval --align sim3` reports.
  RpeResult s = compute_rpe(f.est, f.gt, 1.0, "seconds", with(Alignment::sim3));
  expect_stats(s.trans, 0.02827761861610078, 0.02724474316263279, 0.027342985619755327, 0.007572825404023469,
               0.01229766758179932, 0.04728847167201754);
}
