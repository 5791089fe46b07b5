// Offline refinement of a tracked trajectory (any tracker): keyframes, overlapping keyframe pairs,
// dense pairwise alignment of each pair with our Tracker (point-to-plane + photometric, frame to
// frame), and a pose graph over the keyframe poses solved with Ceres; non-keyframe poses follow
// their keyframes' corrections by interpolation. The formulation (keyframe graph of dense RGB-D
// alignments with their information matrices) is DVO-SLAM's (Kerl, Sturm, Cremers, "Dense Visual
// SLAM for RGB-D Cameras", IROS 2013, sec. IV) and the pose-graph objective is that of Choi, Zhou,
// Koltun, "Robust Reconstruction of Indoor Scenes", CVPR 2015, eq. 2-4 (robust kernel on each
// pairwise edge instead of their line processes). docs/TRACKING.md, "Ceres refinement".
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/device.hpp"
#include "io/frame_source.hpp"
#include "io/trajectory.hpp"
#include "recon/preprocess_params.hpp"
#include "recon/refine/refine_params.hpp"

namespace seamless {

// What the refinement did: written as refine_stats.csv and logged.
struct RefineStats {
  std::int64_t frames = 0;
  std::int64_t keyframes = 0;
  std::int64_t candidate_pairs = 0;  // non-consecutive pairs that passed the pose and overlap tests
  std::int64_t pair_edges = 0;       // aligned pairs kept as edges (consecutive ones included)
  std::int64_t rejected_pairs = 0;   // aligned but rejected (inliers, correction, degenerate)
  std::int64_t odometry_edges = 0;
  int iterations = 0;  // Ceres iterations
  double initial_cost = 0, final_cost = 0;
  bool converged = false;         // Ceres reported convergence
  double max_correction_m = 0;    // largest change of a keyframe position
  double max_correction_deg = 0;  // largest change of a keyframe orientation
  double seconds = 0;             // wall time of the whole stage
  std::string message;            // Ceres' one-line report, or why nothing was done
};

struct RefineResult {
  Trajectory trajectory;                // one pose per input pose (refined, or the input when a no-op)
  std::vector<std::int64_t> keyframes;  // indices into the trajectory
  RefineStats stats;
};

// Throws seamless::Error naming libceres-dev when params.enabled or params.online and this build has no Ceres.
void require_refine(const RefineParams& params);
bool refine_available();

// Keyframe indices into `odometry` (the first tracked pose is always one; lost frames never are).
// tracked: one flag per pose (empty = all tracked).
std::vector<std::int64_t> select_keyframes(const Trajectory& odometry, const RefineParams& params,
                                           const std::vector<bool>& tracked = {});

// Refines `odometry`, the poses of the frames `source` delivers in order (one pose per frame, as
// track_sequence writes them). Reads the source once and keeps only the keyframes. Fewer than two
// keyframes, or no edge beyond the odometry: a no-op with a warning (result = input, stats.message
// says why). Throws seamless::Error when the source and the trajectory disagree in length.
RefineResult refine_trajectory(FrameSource& source, const Trajectory& odometry, const RefineParams& params,
                               const PreprocessParams& preprocess, Device device,
                               const std::vector<bool>& tracked = {});

// Key, value rows (keyframes, edges, Ceres iterations, costs, ...).
void write_refine_stats(const std::string& path, const RefineStats& stats);

// `seamless track` with refine.enabled: renames out_dir/trajectory.txt to trajectory_odometry.txt,
// refines, writes the refined trajectory.txt and refine_stats.csv, logs the summary.
RefineResult refine_run(const InputParams& input, const Trajectory& odometry, const std::vector<bool>& tracked,
                        const RefineParams& params, const PreprocessParams& preprocess, Device device,
                        const std::string& out_dir);

}  // namespace seamless
