// Refine section (`refine:`): an offline stage after any tracker that reduces drift with a keyframe
// pose graph solved by Ceres (Kerl et al. 2013, DVO-SLAM; Choi et al. 2015). See
// docs/TRACKING.md, "Ceres refinement", and src/recon/refine/refine.hpp.
#pragma once
#include <string>
#include <vector>

#include "core/params.hpp"
#include "recon/tracker_params.hpp"

namespace seamless {

enum class KeyframeRule { every, motion };
inline std::span<const EnumName<KeyframeRule>> enum_names(KeyframeRule) {
  static constexpr EnumName<KeyframeRule> names[] = {{KeyframeRule::every, "every"}, {KeyframeRule::motion, "motion"}};
  return names;
}
enum class PairTracker { icp, rgbd };
inline std::span<const EnumName<PairTracker>> enum_names(PairTracker) {
  static constexpr EnumName<PairTracker> names[] = {{PairTracker::icp, "icp"}, {PairTracker::rgbd, "rgbd"}};
  return names;
}
enum class RobustLoss { none, huber, cauchy };
inline std::span<const EnumName<RobustLoss>> enum_names(RobustLoss) {
  static constexpr EnumName<RobustLoss> names[] = {
      {RobustLoss::none, "none"}, {RobustLoss::huber, "huber"}, {RobustLoss::cauchy, "cauchy"}};
  return names;
}

struct RefineParams {
  bool enabled = false;
  bool online = false;                           // the graph grown and solved while tracking runs (online_refine.hpp)
  KeyframeRule keyframes = KeyframeRule::every;  // every keyframe_every frames, or by motion
  int keyframe_every = 10;                       // frames
  float keyframe_translation = 0.1f;             // motion mode: metres since the last keyframe
  float keyframe_rotation_deg = 15.f;            // motion mode: degrees since the last keyframe (1/4 of the view)
  float max_pair_translation = 0.5f;             // candidate pairs: odometry poses at most this far apart, metres
  float max_pair_rotation_deg = 30.f;            // ... and at most this much rotated, degrees
  float min_overlap = 0.3f;        // candidate pairs: share of keyframe j's pixels that land on i's surface
  int max_pairs_per_keyframe = 6;  // non-consecutive partners per keyframe (the most overlapping)
  PairTracker pair_tracker = PairTracker::rgbd;  // dense pairwise alignment (our Tracker, frame to frame)
  std::vector<int> iterations{10, 5, 4};         // pairwise alignment per pyramid level, finest first; 0 skips a level
  float photometric_weight = 1.f;                // rgbd pairwise alignment: colour term weight
  RgbdWeighting weighting = RgbdWeighting::fixed;  // rgbd pairwise alignment: as tracker.weighting
  DepthNoiseModel depth_noise =
      DepthNoiseModel::uniform;  // rgbd pairwise alignment, weighting robust: as tracker.depth_noise
  PhotometricPixels photometric_pixels =
      PhotometricPixels::inliers;       // rgbd pairwise alignment: as tracker.photometric_pixels
  float min_pair_inlier_ratio = 0.3f;   // an aligned pair is kept above this inlier ratio
  float max_pair_correction = 0.1f;     // ... and when it moves the odometry's relative pose less, metres
  float max_pair_correction_deg = 5.f;  // ... and degrees
  float information_samples = 1000.f;   // independent samples a dense alignment is worth (pixels correlate)
  float odometry_weight = 1.f;          // odometry edge vs an alignment of the same pair, / frames between
  RobustLoss robust_loss = RobustLoss::huber;
  float robust_scale = 3.f;  // in whitened units (standard deviations)
  int max_iterations = 100;  // Ceres Levenberg-Marquardt iterations

  template <class V> void visit(V& v) {
    v("enabled", enabled, "refine the tracked trajectory with a keyframe pose graph (needs Ceres, libceres-dev)");
    v("online", online,
      "refine while tracking runs: keyframes handed to a background thread that aligns them and "
      "re-solves the graph; the tracker's pose follows the newest solution (needs Ceres; docs/TRACKING.md, "
      "'Online refinement')");
    v("keyframes", keyframes,
      "keyframe selection: every keyframe_every frames, or when the motion since the last "
      "keyframe exceeds keyframe_translation / keyframe_rotation_deg");
    v("keyframe_every", keyframe_every, "frames between keyframes (keyframes: every)", Range{1, 1e6});
    v("keyframe_translation", keyframe_translation, "keyframes: motion; metres since the last keyframe",
      Range{0.0, 100.0});
    v("keyframe_rotation_deg", keyframe_rotation_deg, "keyframes: motion; degrees since the last keyframe",
      Range{0.0, 180.0});
    v("max_pair_translation", max_pair_translation, "keyframe pairs are candidates up to this distance, metres",
      Range{0.0, 100.0});
    v("max_pair_rotation_deg", max_pair_rotation_deg, "keyframe pairs are candidates up to this rotation, degrees",
      Range{0.0, 180.0});
    v("min_overlap", min_overlap,
      "keyframe pairs are candidates when this share of one's pixels finds a "
      "correspondence in the other (coarsest level, at the odometry's relative pose)",
      Range{0.0, 1.0});
    v("max_pairs_per_keyframe", max_pairs_per_keyframe, "most overlapping non-consecutive partners per keyframe",
      Range{0, 1000});
    v("pair_tracker", pair_tracker, "dense alignment of a keyframe pair (our tracker, frame to frame)");
    v("iterations", iterations,
      "pairwise alignment iterations per pyramid level, finest first (0 skips a level: "
      "a subsampled alignment)",
      Range{0, 1000});
    v("photometric_weight", photometric_weight, "pair_tracker rgbd: weight of the colour term", Range{0.0, 1e6});
    v("weighting", weighting, "pair_tracker rgbd: fixed (photometric_weight) or robust weights (as tracker.weighting)");
    v("depth_noise", depth_noise,
      "pair_tracker rgbd, weighting robust: geometric noise uniform or growing with "
      "depth squared (as tracker.depth_noise)");
    v("photometric_pixels", photometric_pixels,
      "pair_tracker rgbd: photometric rows for the geometric inliers "
      "only, or for every pixel that sees the other keyframe's surface (as tracker.photometric_pixels)");
    v("min_pair_inlier_ratio", min_pair_inlier_ratio, "an aligned pair becomes an edge above this inlier ratio",
      Range{0.0, 1.0});
    v("max_pair_correction", max_pair_correction,
      "an aligned pair is rejected when it moves the odometry's "
      "relative pose more than this, metres",
      Range{0.0, 100.0});
    v("max_pair_correction_deg", max_pair_correction_deg, "... or more than this, degrees", Range{0.0, 180.0});
    v("information_samples", information_samples,
      "independent samples one dense alignment is worth: its 6x6 "
      "information is scaled to this many pixels (neighbouring pixels' errors correlate)",
      Range{1.0, 1e9});
    v("odometry_weight", odometry_weight,
      "weight of an odometry edge relative to a pairwise alignment of the "
      "same keyframes, divided by the frames between them (the odometry is a chain of that many alignments)",
      Range{0.0, 1e6});
    v("robust_loss", robust_loss, "robust loss on each edge's whitened residual");
    v("robust_scale", robust_scale, "scale of the robust loss, in standard deviations", Range{1e-6, 1e6});
    v("max_iterations", max_iterations, "Ceres solver iterations", Range{1, 100000});
  }
};

}  // namespace seamless
