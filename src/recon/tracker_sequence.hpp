// Tracking a whole sequence: the per-frame loop of KinectFusion (preprocess, track against the
// reference view, fuse, raycast the next reference) with loss handling, gravity alignment and
// the outputs trajectory.txt (TUM) and tracking_stats.csv. `seamless track` is a thin wrapper
// around track_sequence(); `seamless run` can drive TrackingSession frame by frame and share the
// volume with the physics.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/timing.hpp"
#include "io/frame_source.hpp"
#include "io/trajectory.hpp"
#include "recon/dynamic_params.hpp"
#include "recon/external/odometry.hpp"
#include "recon/mask_score.hpp"
#include "recon/preprocess.hpp"
#include "recon/tracker.hpp"
#include "recon/tracker_gravity.hpp"
#include "recon/volume.hpp"

namespace seamless {

struct FrameRecord;

// A hook after every processed frame (refine.online, src/recon/refine/online_refine.hpp): it may
// return a correction delta (corrected world = delta * world) that the caller applies with
// TrackingSession::correct before the next frame.
class PoseCorrector {
 public:
  virtual ~PoseCorrector() = default;
  virtual std::optional<SE3> after_frame(const RgbdFrame& frame, const FrameRecord& rec) = 0;
};

// The sections of an experiment that tracking reads (from Experiment: tracker, preprocess, volume,
// frames).
struct TrackSequenceParams {
  TrackerParams tracker;
  PreprocessParams preprocess;
  VolumeParams volume;
  DynamicParams dynamic;        // dynamic pixels out of tracking and fusion (off by default)
  std::int64_t max_frames = 0;  // 0 = all the source has
  bool write_files = true;      // trajectory.txt and tracking_stats.csv into out_dir
  // When set, the volume's kernel steps (allocate, visible, fuse, remove_empty, raycast) are timed
  // into it, one end_frame(frame index) a processed frame, and FrameRecord::allocate_ms is filled
  // (`seamless bench pipeline`). Off in ordinary runs: on CUDA each step costs two more events.
  StageTimer* volume_stages = nullptr;
  // refine.online: sees every frame; its corrections move the session's pose (track_sequence).
  PoseCorrector* corrector = nullptr;
  // tracker.kind trajectory: the k-th frame processed takes pose k of this list instead of the
  // pose at its timestamp in tracker.trajectory's file; none (or past the end): not fused. A
  // scan's fusion pass at the refined poses (src/app/pipeline.cpp) sees the same frames again.
  std::shared_ptr<const std::vector<std::optional<SE3>>> frame_poses;
  // >= 0: this pyramid level's vertex and normal maps are also kept as they were before the
  // dynamic mask zeroed them (TrackingSession::unmasked_level; the live colliders of solver.dynamic_colliders).
  int keep_unmasked_level = -1;
  // The session's own model (frame-to-model tracking, or dynamic handling with another mode, and no
  // volume given) marched into TrackSequenceResult::model_mesh at the end (`seamless track`'s ghost
  // measure).
  bool keep_model_mesh = false;
};

// One frame's outcome, one row of tracking_stats.csv.
struct FrameRecord {
  std::int64_t frame = 0;
  double timestamp = 0;
  TrackResult result;  // result.world_T_camera is the pose written for this frame
  bool fused = false;  // integrated into the volume (never when tracking was lost)
  // Times on the device's timeline (CUDA events; the host clock on the CPU): preprocess includes
  // the upload, fuse the raycast of the next reference view (the columns of tracking_stats.csv).
  double preprocess_ms = 0, track_ms = 0, fuse_ms = 0, frame_ms = 0;
  // Parts of those: upload_ms of preprocess_ms (the frame's host-to-device copies), raycast_ms of
  // fuse_ms (the next reference view: raycast and its pyramid), allocate_ms of fuse_ms (block
  // allocation and the visible-block list; NaN unless TrackSequenceParams::volume_stages is set).
  double upload_ms = 0, raycast_ms = 0, allocate_ms = std::numeric_limits<double>::quiet_NaN();
  // dynamic_ms of track_ms: the dynamic pixels (dynamic.enabled; the mask before tracking and the
  // mask at the tracked pose, docs/DYNAMIC.md), 0 otherwise.
  double dynamic_ms = 0;
  // dynamic.enabled: the fraction of the frame's pixels in its dynamic mask (NaN when off).
  double dynamic_fraction = std::numeric_limits<double>::quiet_NaN();
  // dynamic.enabled on a source with the movers' ground truth (the synthetic room's movers): the
  // mask against it (recon/mask_score.hpp); none for a frame without a mask (the first, a lost one).
  std::optional<MaskScore> mask_score;
};

// The per-frame state machine. World frame: the first camera, rotated so that gravity is world -y
// when tracker.gravity finds it. A lost frame keeps the last good pose, is not fused, and the
// reference stays the last good view, so the next frames try to recover against it: from the last
// good pose (the motion model is stale), and accepted only when the pose moved no more than the
// time lost allows and the frame fits the model as well as the good frames did.
// External trackers (registry entries with make_external: OpenCV, PCL) are frame to frame whatever
// tracker.mode says: their relative poses prev_T_cur are chained from the same world frame, against
// the last good frame, and a frame the library fails on is lost like ours (docs/TRACKING.md).
class TrackingSession {
 public:
  // volume: the model for frame-to-model tracking. nullptr: the session makes its own from
  // params.volume when the mode is frame_to_model. A volume that is given is always fused into.
  TrackingSession(const TrackSequenceParams& params, Device device, const Intrinsics& K, Volume* volume = nullptr);
  ~TrackingSession();
  FrameRecord process(const RgbdFrame& frame);
  // Moves the session's pose, its motion model and its reference view by `delta` (world' = delta *
  // world): the next frames are tracked and fused in the corrected frame (refine.online).
  void correct(const SE3& delta);

  Volume* volume() const { return volume_; }
  const GravityEstimate& gravity() const { return gravity_; }
  std::int64_t lost_frames() const { return lost_; }
  const ReferenceMaps& reference() const { return ref_; }
  const FramePyramid& pyramid() const { return pyr_; }
  // dynamic.enabled: the last processed frame's dynamic pixels (1) on the session's device, full
  // resolution; empty before the first frame with a model to compare with (docs/DYNAMIC.md).
  const Image<std::uint8_t>& dynamic_mask() const { return dyn_mask_; }
  // The last frame's pyramid level params.keep_unmasked_level (vertices, then normals) with its
  // dynamic pixels still in it; the pyramid's own level when nothing was masked.
  std::pair<const Image<vec3>*, const Image<vec3>*> unmasked_level() const;
  // Whether unmasked_level() holds this frame's level as it was before the mask zeroed the people.
  bool has_unmasked_level() const { return kept_; }

 private:
  bool uses_volume() const;
  void upload(const RgbdFrame& frame);
  void preprocess();  // the pyramid (and intensity) of the uploaded frame
  void upload_colour(const RgbdFrame& frame);
  void join_colour();  // the default stream waits for the colour upload
  void first_frame(const RgbdFrame& frame, FrameRecord& rec);
  TrackResult track_frame(const RgbdFrame& frame);
  TrackResult track_external(const RgbdFrame& frame);
  TrackResult given_pose(const RgbdFrame& frame) const;  // tracker.kind trajectory
  TrackResult relocalise(const RgbdFrame& frame);
  void check_cut(TrackResult& r) const;
  void check_relocalisation(const RgbdFrame& frame, TrackResult& r) const;
  SE3 last_motion(std::int64_t frames) const;  // the last frame-to-frame motion, repeated `frames` times
  void accept(const RgbdFrame& frame, const SE3& pose, FrameRecord& rec);
  double volume_allocate_ms(std::size_t first_row) const;
  void update_reference(const SE3& pose);
  // Frame to frame with tracker.keyframe_min_overlap: whether the frame just accepted keeps the
  // keyframe as the reference (its overlap with it still holds).
  bool keeps_keyframe(const FrameRecord& rec);
  // Dynamic pixels: the model to compare with (ref_ when tracking frame to model, else
  // a raycast of the volume from the last good pose; nullptr without a volume), and the mask of the
  // current frame at pose world_T_camera into dyn_mask_: the frame's (final, at the tracked pose)
  // or the tracker's (before tracking: without the evidence of the past views).
  const ReferenceMaps* dynamic_reference();
  const ReferenceMaps* mask_before_tracking();  // dynamic_reference(), and the tracker's pixels masked
  void find_dynamic(const ReferenceMaps& model, const SE3& world_T_camera, bool final);
  void remember_view(const SE3& world_T_camera);  // free_space_evidence views: keep this frame's depth

  TrackSequenceParams p_;
  Device device_;
  Intrinsics K_;
  std::unique_ptr<Volume> own_volume_;
  Volume* volume_ = nullptr;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<external::Odometry> odometry_;  // external kinds only
  RgbdFrame last_good_frame_;                     // external kinds: host copy of the last frame accepted
  FramePyramid pyr_;
  ReferenceMaps ref_;
  RaycastMaps maps_;
  ReferenceMaps dyn_ref_;  // frame-to-frame tracking: the model raycast the mask compares with
  RaycastMaps dyn_maps_;
  Image<std::uint8_t> dyn_candidates_, dyn_kept_, dyn_mask_, dyn_prev_;
  // The candidates' ages and anchors (kernels::Dynamic::age_dynamic): this frame's, and the
  // previous frame's with its pose.
  Image<std::uint8_t> dyn_age_, dyn_prev_age_;
  Image<float> dyn_anchor_, dyn_prev_anchor_;
  SE3 dyn_prev_pose_ = SE3::identity();
  // free_space_evidence views: the kept depth maps (a ring), their cameras, the next slot to fill,
  // and the frames remember_view has seen.
  std::vector<Image<float>> dyn_views_;
  Image<float> dyn_prev_depth_;  // the previous frame's depth (level 0), for the continuation of its kept pixels
  std::vector<SE3> dyn_view_T_world_;
  std::size_t dyn_view_next_ = 0;
  std::int64_t dyn_view_frames_ = 0;
  Image<vec3> kept_vertices_, kept_normals_;  // params.keep_unmasked_level before masking
  bool kept_ = false;                         // they hold this frame's level
  Image<float> depth_, intensity_;
  Image<uchar3> rgb_;
  GravityEstimate gravity_;
  DeviceMarks marks_;
  struct ColourUpload;
  std::unique_ptr<ColourUpload> colour_upload_;
  bool started_ = false;
  SE3 last_good_ = SE3::identity(), prev_good_ = SE3::identity();
  SE3 world_T_gt_ = SE3::identity();  // ground_truth tracker: maps the source's poses into our world
  // trajectory tracker: the file's poses (in their own world frame), or params.frame_poses.
  std::shared_ptr<const Trajectory> given_;
  bool given_poses_ = false;
  std::int64_t processed_ = 0;  // frames processed so far (the index into params.frame_poses)
  std::int64_t lost_ = 0;
  std::int64_t lost_run_ = 0;           // consecutive lost frames just before this one: > 0 means relocalising
  double last_good_time_ = 0;           // timestamp of the last good frame
  double last_inlier_ratio_ = 0;        // of the last frame tracked (not the first), 0 before
  double keyframe_inlier_ratio_ = 0;    // of the first frame tracked against the keyframe; 0: none yet
  std::vector<double> good_residuals_;  // residual_rms of the last good tracked frames (at most 10)
};

struct TrackSequenceResult {
  Trajectory trajectory;    // one pose per frame (a lost frame: the last good pose)
  Trajectory ground_truth;  // the source's poses of the frames that have one, in the same world frame
  std::vector<FrameRecord> frames;
  std::int64_t lost_frames = 0;
  GravityEstimate gravity;
  double median_track_ms = 0;
  double median_frame_ms = 0;
  std::optional<Mesh> model_mesh;  // params.keep_model_mesh and the session built a model
};

// Tracks every frame of `source` (up to params.max_frames), writes out_dir/trajectory.txt and
// out_dir/tracking_stats.csv when params.write_files, and returns both in memory; frames with ground
// truth (TUM groundtruth.txt, frame-folder pose files, the synthetic room) also give
// out_dir/groundtruth.txt, their poses re-expressed in the run's world frame. on_frame, if
// given, sees each frame after it was processed (progress, rendering).
TrackSequenceResult track_sequence(FrameSource& source, const TrackSequenceParams& params, Device device,
                                   const std::string& out_dir, Volume* volume = nullptr,
                                   const std::function<void(const RgbdFrame&, const FrameRecord&)>& on_frame = {});

// tracking_stats.csv: frame, timestamp, status, fused, inlier_ratio, inliers, residual_rms,
// condition, iterations, translation_jump_m, rotation_jump_deg, preprocess_ms, track_ms, fuse_ms,
// frame_ms.
void write_tracking_stats(const std::string& path, const std::vector<FrameRecord>& frames);

// dynamic.write_masks: out_dir/dynamic_mask/<frame index, 6 digits>.png, 255 where the session's
// last frame is dynamic (an empty mask before the first frame with a model). `seamless track` and
// `seamless run` both write them.
void write_dynamic_mask(const std::string& out_dir, std::int64_t index, const TrackingSession& session);
// The run's mask quality from the frames' mask scores (recon/mask_score.hpp; people: the persons'
// mover ids); nothing when no frame has one (dynamic handling off, or a source without the movers'
// ground truth).
std::optional<MaskQuality> mask_quality(const std::vector<FrameRecord>& frames, const std::vector<int>& people);

// The trackers this build knows (tracker.kind values): every entry says whether it is available and,
// if not, what to install. Adding a tracker is one entry in tracker_registry() plus its
// implementation: our own kinds are driven by Tracker, an external one by the Odometry its
// make_external builds (src/recon/external/odometry.hpp).
struct TrackerInfo {
  std::string kind;
  std::string description;
  bool available;
  std::string missing;                      // what to install when not available
  external::OdometryFactory make_external;  // external frame-to-frame trackers only
};
const std::vector<TrackerInfo>& tracker_registry();
// Throws seamless::Error naming the fix when `kind` is unknown or not built in.
void require_tracker(const std::string& kind);
// The registry entry of `kind` (require_tracker's checks first).
const TrackerInfo& tracker_info(const std::string& kind);

}  // namespace seamless
