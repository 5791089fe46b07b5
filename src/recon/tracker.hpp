// Camera tracking after KinectFusion (Newcombe et al. 2011, section 3.5): point-to-plane ICP with
// projective data association over a 3-level pyramid, coarse to fine, against a reference view
// (the model raycast for frame-to-model, the previous frame for frame-to-frame); optionally with a
// photometric term (RGB-D). Each Gauss-Newton iteration is one device reduction of the 6x6 normal
// equations and one 6x6 Cholesky solve and pose update on the device (kernels/recon/icp.hpp); the
// host reads the result once per frame.
// Tracking loss is detected, not hidden: see TrackStatus. docs/TRACKING.md has the details.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "kernels/recon/icp.hpp"
#include "kernels/recon/rgbd.hpp"
#include "recon/preprocess.hpp"
#include "recon/tracker_params.hpp"

namespace seamless {

struct RaycastMaps;

// One level of a reference view, in the coordinates of the camera it was seen or rendered from.
struct ReferenceLevel {
  Intrinsics K;
  Image<vec3> vertices;
  Image<vec3> normals;
  Image<float> intensity;  // empty when the reference has no colour
};

// What a frame is aligned to. Owns its images (device of the tracker), so the frame pyramid or
// raycast it came from can be reused for the next frame.
class ReferenceMaps {
 public:
  // Frame-to-frame: a copy of a frame's pyramid, seen from world_T_camera.
  void set_from_frame(const FramePyramid& frame, const SE3& world_T_camera);
  // Frame-to-model: a raycast (world-space maps, full resolution, intrinsics K) rendered from
  // world_T_camera, moved into that camera's coordinates and subsampled into `levels` levels.
  // max_diff: largest depth difference averaged by the subsampling, metres.
  // photometric: when given (a frame seen from world_T_camera, normally the last tracked one), its
  // intensity pyramid is the photometric reference instead of the raycast's fused colour; see
  // TrackerParams::photometric_reference. with_intensity = false: no intensity at all (a geometric
  // tracker reads none, and its conversion and pyramid would be wasted work).
  void set_from_raycast(const RaycastMaps& maps, const Intrinsics& K, const SE3& world_T_camera, int levels,
                        float max_diff = 0.09f, const FramePyramid* photometric = nullptr, bool with_intensity = true);
  // Whether set_from_raycast with these arguments reads the raycast's colour (so that the raycast
  // may leave it out: RaycastMaps::with_color).
  static bool reads_model_colour(const Intrinsics& K, int levels, const FramePyramid* photometric, bool with_intensity);
  const ReferenceLevel& level(int l) const { return levels_.at(l); }
  int levels() const { return static_cast<int>(levels_.size()); }
  bool empty() const { return levels_.empty(); }
  bool has_intensity() const { return !levels_.empty() && levels_[0].intensity.width() > 0; }
  const SE3& world_T_ref() const { return world_T_ref_; }
  // The same maps seen from a corrected world (world' = delta * world): their own frame is unchanged.
  void move_world(const SE3& delta) { world_T_ref_ = delta * world_T_ref_; }

 private:
  void resize(const Intrinsics& K, int levels, Device d, bool intensity);
  std::vector<ReferenceLevel> levels_;
  SE3 world_T_ref_ = SE3::identity();
};

enum class TrackStatus {
  ok,
  too_few_inliers,   // inliers / valid pixels below tracker.min_inlier_ratio
  implausible_jump,  // more motion than tracker.max_translation_jump / max_rotation_jump_deg
  degenerate,        // the 6x6 system is singular or worse conditioned than tracker.max_condition
  no_reference,      // nothing to align to (first frame, or no ground truth for this frame)
  // after lost frames: the estimate moved farther than the time lost allows, or fits the model
  // worse than the good frames did (tracker.relocalise_*); the next frame tries again
  relocalisation_rejected,
};
const char* to_string(TrackStatus s);

// Quality of one tracked frame (docs/TRACKING.md, "Per-frame statistics").
struct TrackResult {
  SE3 world_T_camera = SE3::identity();  // the estimate; the initial guess when the solve failed
  TrackStatus status = TrackStatus::no_reference;
  double residual_rms = 0;  // sqrt(error / inliers) of the last finest-level iteration (metres for ICP)
  double inlier_ratio = 0;  // finest level: correspondences / pixels with a vertex
  std::int64_t inliers = 0;
  double condition = 0;         // eigenvalue ratio of the finest level's J^T J
  int iterations = 0;           // Gauss-Newton steps taken, all levels
  double translation_jump = 0;  // metres between the initial guess and the estimate
  double rotation_jump_deg = 0;
  bool ok() const { return status == TrackStatus::ok; }
};

class Tracker {
 public:
  Tracker(const TrackerParams& params, Device device);
  // Aligns `frame` to `ref` starting from initial_world_T_camera (coarse to fine, params.iterations
  // per level, finest first). Checks the result for tracking loss; a lost result still carries
  // the estimate and its statistics.
  TrackResult track(const FramePyramid& frame, const ReferenceMaps& ref, const SE3& initial_world_T_camera) const;
  // The normal equations of one level at ref_T_cur (one reduction; for tests and benchmarks).
  kernels::IcpSums reduce(const FramePyramid& frame, const ReferenceMaps& ref, int level, const SE3& ref_T_cur) const;
  const TrackerParams& params() const { return params_; }
  // Whether the tracker has a photometric term (RGB-D with a positive weight): only then does it
  // read the intensity of frames and references.
  bool reads_intensity() const { return params_.kind == "rgbd" && params_.photometric_weight > 0; }
  Device device() const { return device_; }

 private:
  bool use_photometric(const FramePyramid& frame, const ReferenceMaps& ref) const;
  bool robust(const FramePyramid& frame, const ReferenceMaps& ref) const;
  // steps = 0: one reduction of the level's system at the device estimate, no step; else up to
  // `steps` Gauss-Newton steps of the level in one launch. The system goes to sums_slot(level).
  void reduce_into(const FramePyramid& frame, const ReferenceMaps& ref, int level, int steps) const;
  kernels::IcpState* state() const;
  kernels::IcpSums* sums_slot(int level) const;
  void set_pose(const SE3& ref_T_cur) const;
  void check_loss(TrackResult& r, const SE3& initial) const;
  TrackerParams params_;
  Device device_;
  // Device state of the Gauss-Newton loop (reused from frame to frame): the estimate and one
  // system per level.
  mutable Buffer<kernels::IcpState> state_;
  // RGB-D: the full sums of the last reduction (the system plus the residual statistics of the
  // robust weighting); its system is copied into state_'s level slot on the device.
  mutable Buffer<kernels::RgbdSums> rgbd_sums_;
};

// One Gauss-Newton step on the host (tests, statistics): solves J^T J xi = -J^T r with the device
// loop's Cholesky (kernels::solve_normal_equations) and reports the condition number of J^T J (largest / smallest
// eigenvalue; infinity when singular).
struct IcpStep {
  double xi[6] = {0, 0, 0, 0, 0, 0};  // omega (rad), upsilon (m)
  double condition = 0;
  bool solved = false;
};
IcpStep solve_icp_step(const kernels::IcpSums& s);
// exp(xi) as a rigid transform: Rodrigues rotation of omega, translation upsilon (the left update of
// kernels/recon/icp.hpp, first order in xi like KinectFusion eq. 19, then kept exactly rigid).
SE3 se3_exp(const double xi[6]);
// Rotation angle of R in degrees.
double rotation_angle_deg(const mat3& R);

}  // namespace seamless
