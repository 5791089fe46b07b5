// The steps of the keyframe refinement (internal to src/recon/refine), shared by the offline stage
// (refine.cpp: the whole trajectory at once) and the online one (online_refine.cpp: keyframe by
// keyframe while tracking runs). docs/TRACKING.md, "Ceres refinement" and "Online refinement".
#pragma once
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "io/frame_source.hpp"
#include "io/trajectory.hpp"
#include "recon/preprocess.hpp"
#include "recon/refine/refine.hpp"
#include "recon/refine/refine_graph.hpp"
#include "recon/tracker.hpp"

namespace seamless::refine_detail {

Pose to_pose(const TumPose& p);
TumPose to_tum(double timestamp, const Pose& p);
SE3 to_se3(const Pose& p);
Pose from_se3(const SE3& T);
// Rotation (degrees) and translation (metres) of b relative to a.
std::pair<double, double> distance(const Pose& a, const Pose& b);

// Whether the pose at `index` is a new keyframe after the one at last_index (refine.keyframes:
// every keyframe_every frames, or by motion since the last keyframe).
bool keyframe_due(const Pose& last_keyframe, std::int64_t last_index, const Pose& pose, std::int64_t index,
                  const RefineParams& p);

// One keyframe's pyramid on the device (kept for the whole stage: a 640x480 pyramid is ~13 MB).
struct KeyframeData {
  std::int64_t frame = 0;
  double timestamp = 0;
  Pose odometry;
  std::unique_ptr<FramePyramid> pyr;
};
std::unique_ptr<FramePyramid> build_pyramid(const RgbdFrame& f, const Intrinsics& K, const PreprocessParams& pre,
                                            bool colour, Device d);

// The pairwise tracker (frame to frame, no loss tests of its own) and the level its statistics
// come from.
TrackerParams pair_tracker_params(const RefineParams& p);
int finest_level(const RefineParams& p, int levels);

// Share of b's pixels (coarsest level) that find a correspondence on a's surface at the odometry's
// relative pose; ref_a holds a's pyramid seen from the identity.
double overlap(const Tracker& tracker, const KeyframeData& a, const KeyframeData& b, const ReferenceMaps& ref_a);

struct Graph {
  std::vector<Edge> edges;
  RefineStats stats;
};
// Edges between keyframes kf[i] = a and kf[j] = b (i < j), ref_a holding a's pyramid: the
// odometry edge of consecutive keyframes (j = i + 1), and the dense pairwise alignment (an edge
// unless rejected; a loop edge, robust, when j > i + 1).
void add_odometry_edge(Graph& g, const Tracker& tracker, const KeyframeData& a, const KeyframeData& b,
                       const ReferenceMaps& ref_a, int i, const RefineParams& p, int level);
void add_pair_edge(Graph& g, const Tracker& tracker, const KeyframeData& a, const KeyframeData& b, ReferenceMaps& ref_a,
                   int i, int j, const RefineParams& p, int level);
// The max_pairs_per_keyframe most overlapping of (overlap, keyframe) candidates.
std::vector<int> best_partners(std::vector<std::pair<double, int>> cand, const RefineParams& p);

// Every pose of `odometry` follows the refined keyframes around it (blended by time between them;
// before the first and after the last keyframe: that keyframe's correction).
Trajectory apply_corrections(const Trajectory& odometry, const std::vector<KeyframeData>& kf,
                             const std::vector<Pose>& refined);

}  // namespace seamless::refine_detail
