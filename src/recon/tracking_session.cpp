// TrackingSession (tracker_sequence.hpp): the per-frame state machine of tracking, one frame at a
// time (upload, preprocess, track or relocalise, fuse, raycast the next reference), with the
// dynamic-pixel masks (docs/DYNAMIC.md) and the external trackers. tracker_sequence.cpp drives it over a
// whole sequence and writes the outputs.
#include "recon/tracker_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <utility>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/log.hpp"
#include "core/timing.hpp"
#include "kernels/recon/dynamic.hpp"
#include "kernels/recon/rgbd.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

// Where a frame's stages end on the device's timeline (TrackingSession::marks_).
namespace {
// kMasked and kPosed (dynamic.enabled only) split the track stage: the mask before tracking, the
// pose, the mask at the pose.
enum Mark { kStart, kUploaded, kPreprocessed, kMasked, kPosed, kTracked, kFused, kEnd, kMarks };
}  // namespace

// The colour image goes up on a stream of its own: only fusion (and the RGB-D tracker's intensity)
// reads it, so its copy overlaps preprocessing and tracking instead of delaying them.
struct TrackingSession::ColourUpload {
#if SEAMLESS_HAS_CUDA
  std::unique_ptr<CudaStream> stream;  // made on the first CUDA upload: a CPU run needs no driver
#endif
  bool pending = false;
};

namespace {
// A frame the session keeps beyond the source's next() (which may reuse its images).
RgbdFrame host_copy(const RgbdFrame& f) {
  RgbdFrame c;
  c.index = f.index;
  c.timestamp = f.timestamp;
  if (f.depth.width() > 0) c.depth = f.depth.clone(Device::CPU);
  if (f.rgb.width() > 0) c.rgb = f.rgb.clone(Device::CPU);
  c.intrinsics = f.intrinsics;
  c.accelerometer = f.accelerometer;
  c.ground_truth = f.ground_truth;
  return c;
}
}  // namespace

TrackingSession::TrackingSession(const TrackSequenceParams& params, Device device, const Intrinsics& K, Volume* volume)
    : p_(params), device_(device), K_(K), volume_(volume), pyr_(device, K, params.preprocess.levels),
      marks_(device, kMarks), colour_upload_(std::make_unique<ColourUpload>()) {
  const TrackerInfo& info = tracker_info(p_.tracker.kind);
  if (info.make_external) {
    odometry_ = info.make_external(K, p_.tracker);
    if (p_.tracker.mode != TrackingMode::frame_to_frame)
      spdlog::info("tracker.kind {} is frame to frame (tracker.mode {} does not apply)", p_.tracker.kind,
                   enum_name(p_.tracker.mode));
  } else if (p_.tracker.kind == "trajectory") {
    given_poses_ = true;
    if (!p_.frame_poses) {
      if (p_.tracker.trajectory.empty())
        throw ConfigError("tracker.kind: trajectory needs tracker.trajectory, a TUM trajectory file");
      given_ = std::make_shared<const Trajectory>(read_tum_trajectory(p_.tracker.trajectory));
      if (given_->empty()) throw InputError("tracker.trajectory '" + p_.tracker.trajectory + "' holds no pose");
      spdlog::info("tracker: fusing at the {} poses of {}", given_->size(), p_.tracker.trajectory);
    }
  } else if (p_.tracker.kind != "ground_truth") {
    tracker_ = std::make_unique<Tracker>(p_.tracker, device);
  }
  // Our own trackers need a model of their own in frame-to-model mode, and dynamic handling needs
  // one whatever the tracker (it compares each frame with the model: docs/DYNAMIC.md); a volume that
  // is given is fused into by all.
  if (!volume_ && ((p_.tracker.mode == TrackingMode::frame_to_model && tracker_) || p_.dynamic.enabled)) {
    own_volume_ = make_volume(p_.volume, device);
    volume_ = own_volume_.get();
  }
  if (p_.dynamic.enabled) {
    if (p_.dynamic.carve_truncations > 0)
      volume_->set_free_space_carving(p_.dynamic.carve_truncations * volume_->params().truncation);
    // seen_free needs the free space stored: the voxel-hashed volume otherwise knows none away from
    // surfaces, and drops every mover in the middle of the room (docs/DYNAMIC.md).
    if (p_.dynamic.free_space_evidence == FreeSpaceEvidence::seen_free) volume_->set_free_space_storage(true);
  }
}

// ---- dynamic pixels (docs/DYNAMIC.md) -------------------------------------------------------------

const ReferenceMaps* TrackingSession::dynamic_reference() {
  if (tracker_ && p_.tracker.mode == TrackingMode::frame_to_model) return ref_.empty() ? nullptr : &ref_;
  if (!volume_) return nullptr;
  volume_->raycast(K_, last_good_, dyn_maps_);
  dyn_ref_.set_from_raycast(dyn_maps_, K_, last_good_, 1, p_.preprocess.pyramid_max_diff, nullptr, false);
  return &dyn_ref_;
}

std::pair<const Image<vec3>*, const Image<vec3>*> TrackingSession::unmasked_level() const {
  if (kept_) return {&kept_vertices_, &kept_normals_};
  const PyramidLevel& lv = pyr_.level(std::min(std::max(p_.keep_unmasked_level, 0), pyr_.levels() - 1));
  return {&lv.vertices, &lv.normals};
}

// Before tracking, the mask at the pose the tracker starts from (our trackers; the ground-truth
// one needs none) zeroes the dynamic pixels' vertices on every pyramid level: weight 0 in the ICP
// and RGB-D reductions. Relocalising frames start from several poses and keep every pixel.
const ReferenceMaps* TrackingSession::mask_before_tracking() {
  const ReferenceMaps* model = dynamic_reference();
  if (!model) return nullptr;
  if (!tracker_ || odometry_ || lost_run_ > 0) return model;
  find_dynamic(*model, p_.tracker.constant_velocity ? last_good_ * last_motion(1) : last_good_, false);
  if (p_.keep_unmasked_level >= 0 && p_.keep_unmasked_level < pyr_.levels()) {
    const PyramidLevel& lv = pyr_.level(p_.keep_unmasked_level);
    kept_vertices_ = lv.vertices.clone(device_), kept_normals_ = lv.normals.clone(device_);
    kept_ = true;
  }
  with_exec(device_, [&]<class E>(const E& ex) {
    for (int l = 0; l < pyr_.levels(); ++l) {
      PyramidLevel& lv = pyr_.mutable_level(l);
      kernels::Dynamic<E>::mask_vertices(ex, dyn_mask_.cview(), 1 << l, lv.vertices.view(), lv.normals.view());
    }
  });
  return model;
}

void TrackingSession::find_dynamic(const ReferenceMaps& model, const SE3& world_T_camera, bool final) {
  const DynamicParams& d = p_.dynamic;
  if (dyn_mask_.width() != K_.width) {
    for (Image<std::uint8_t>* im : {&dyn_candidates_, &dyn_kept_, &dyn_mask_, &dyn_prev_, &dyn_age_, &dyn_prev_age_})
      *im = Image<std::uint8_t>(K_.width, K_.height, device_);
    dyn_prev_.buffer().zero();      // no previous frame: no temporal support
    dyn_prev_age_.buffer().zero();  // and no candidate has an age yet
    dyn_anchor_ = Image<float>(K_.width, K_.height, device_);
    dyn_prev_anchor_ = Image<float>(K_.width, K_.height, device_);
    dyn_prev_anchor_.buffer().zero();
  }
  const PyramidLevel& l0 = pyr_.level(0);
  const ReferenceLevel& m = model.level(0);
  kernels::DynamicInput in;
  in.depth = l0.depth.cview();
  in.K = K_;
  in.model_vertices = m.vertices.cview();
  in.model_normals = m.normals.cview();
  in.ref_T_cur = model.world_T_ref().inverse() * world_T_camera;
  in.residual_min = d.residual_min;
  in.noise_coeff = d.noise_coeff;
  in.residual_sigmas = d.residual_sigmas;
  in.free_space = d.free_space_truncations * (volume_ ? volume_->params().truncation : p_.volume.truncation);
  in.search_radius = d.search_radius;
  // The views' evidence decides the frame's mask (final). Before tracking, the model test alone
  // masks a superset of its candidates among the pixels the tracker can pair with the model (those
  // with a model surface near): for the pose, a static pixel left out costs little, a mover kept
  // in drags it; and the pass costs no more than without views.
  const bool views = final && d.free_space_evidence == FreeSpaceEvidence::views;
  in.undecided_without_model = views;
  kernels::PastViews past;
  if (views) {
    past.K = K_.level(std::min(d.evidence_view_level, pyr_.levels() - 1));
    for (std::size_t k = 0; k < dyn_views_.size(); ++k)
      past.depth[k] = dyn_views_[k].cview(), past.view_T_world[k] = dyn_view_T_world_[k];
    past.count = static_cast<int>(dyn_views_.size());
  }
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::Dynamic<E>::classify_dynamic(ex, in, dyn_candidates_.view());
    if (views)
      kernels::Dynamic<E>::views_evidence(ex, in, world_T_camera, past, dyn_prev_.cview(), dyn_prev_depth_.cview(),
                                          dyn_prev_pose_.inverse() * world_T_camera, dyn_candidates_.view());
    // Evidence of free space stored in the volume: the volume at the measured points (world frame;
    // the model maps are in the reference camera's). `views` keeps its record outside the volume.
    const bool volume_evidence = d.free_space_evidence == FreeSpaceEvidence::seen_free ||
                                 d.free_space_evidence == FreeSpaceEvidence::not_occupied;
    if (volume_evidence && volume_)
      volume_->require_free_space(l0.depth, K_, world_T_camera, d.evidence_min_weight,
                                  d.free_space_evidence == FreeSpaceEvidence::seen_free, dyn_candidates_);
    if (d.static_after_frames > 0)  // 0: no ageing (and no cost)
      kernels::Dynamic<E>::age_dynamic(ex, in, dyn_prev_anchor_.cview(), dyn_prev_age_.cview(),
                                       dyn_prev_pose_.inverse() * world_T_camera, d.static_after_frames,
                                       dyn_candidates_.view(), dyn_age_.view(), dyn_anchor_.view());
    kernels::Dynamic<E>::filter_dynamic(ex, dyn_candidates_.cview(), dyn_prev_.cview(), l0.depth.cview(),
                                        d.support_radius, d.min_support, d.dilate_max_step, dyn_kept_.view(),
                                        dyn_mask_.view());
  });
}

// Every evidence_view_interval-th frame with a pose, its depth at evidence_view_level (unmasked: a
// mover's readings saw through the space in front of it too) replaces the oldest kept view.
void TrackingSession::remember_view(const SE3& world_T_camera) {
  const DynamicParams& d = p_.dynamic;
  if (dyn_view_frames_++ % std::max(d.evidence_view_interval, 1) != 0) return;
  const PyramidLevel& lv = pyr_.level(std::min(d.evidence_view_level, pyr_.levels() - 1));
  const std::size_t n = static_cast<std::size_t>(std::clamp(d.evidence_views, 1, kernels::PastViews::kMax));
  if (dyn_views_.size() < n) {
    dyn_views_.emplace_back(lv.depth.width(), lv.depth.height(), device_);
    dyn_view_T_world_.push_back(SE3::identity());
    dyn_view_next_ = dyn_views_.size() - 1;
  }
  dyn_views_[dyn_view_next_].buffer().copy_from_async(lv.depth.buffer());
  dyn_view_T_world_[dyn_view_next_] = world_T_camera.inverse();
  dyn_view_next_ = (dyn_view_next_ + 1) % n;
}

TrackingSession::~TrackingSession() = default;

bool TrackingSession::uses_volume() const { return volume_ != nullptr; }

void TrackingSession::upload(const RgbdFrame& frame) {
  if (frame.depth.width() != K_.width || frame.depth.height() != K_.height)
    throw InputError("frame " + std::to_string(frame.index) + " is " + std::to_string(frame.depth.width()) + "x" +
                     std::to_string(frame.depth.height()) + " but the source's intrinsics say " +
                     std::to_string(K_.width) + "x" + std::to_string(K_.height));
  // Persistent device images: one host-to-device copy a frame, no allocation. The copies are
  // asynchronous when the frame is in page-locked memory (what make_source gives a GPU pipeline);
  // process() waits for them before it returns, so the caller may then reuse the frame.
  if (depth_.width() != K_.width) depth_ = Image<float>(K_.width, K_.height, device_);
  depth_.buffer().copy_from_async(frame.depth.buffer());
  bool colour = frame.rgb.width() == K_.width && frame.rgb.height() == K_.height;
  if (colour && rgb_.width() != K_.width) rgb_ = Image<uchar3>(K_.width, K_.height, device_);
  if (colour) upload_colour(frame);
  if (!colour) rgb_ = Image<uchar3>();
}

void TrackingSession::preprocess() {
  const bool colour = rgb_.width() == K_.width;  // upload() keeps rgb_ only for a matching colour image
  const Image<float>* intensity = nullptr;
  if (colour && p_.tracker.kind == "rgbd") {
    if (intensity_.width() != K_.width) intensity_ = Image<float>(K_.width, K_.height, device_);
    join_colour();
    with_exec(device_,
              [&]<class E>(const E& ex) { kernels::Rgbd<E>::rgb_to_intensity(ex, rgb_.cview(), intensity_.view()); });
    intensity = &intensity_;
  }
  pyr_.build(depth_, intensity, p_.preprocess);
}

void TrackingSession::upload_colour(const RgbdFrame& frame) {
#if SEAMLESS_HAS_CUDA
  if (device_ == Device::CUDA) {
    if (!colour_upload_->stream) colour_upload_->stream = std::make_unique<CudaStream>();
    CudaStream& s = *colour_upload_->stream;
    s.after_default();  // the last frame's fusion has read rgb_
    rgb_.buffer().copy_from_async(frame.rgb.buffer(), s.get());
    colour_upload_->pending = true;
    return;
  }
#endif
  rgb_.buffer().copy_from(frame.rgb.buffer());
}

void TrackingSession::join_colour() {
  if (!colour_upload_->pending) return;
#if SEAMLESS_HAS_CUDA
  colour_upload_->stream->before_default();  // pending: made by upload_colour
#endif
  colour_upload_->pending = false;
}

void TrackingSession::update_reference(const SE3& pose) {
  if (volume_ && p_.tracker.mode == TrackingMode::frame_to_model) {
    // The current pyramid is the frame just tracked at `pose`, the pose the raycast is seen from.
    const bool frame_colour = p_.tracker.photometric_reference == PhotometricReference::frame;
    const FramePyramid* photometric = frame_colour ? &pyr_ : nullptr;
    maps_.with_color = ReferenceMaps::reads_model_colour(K_, pyr_.levels(), photometric, tracker_->reads_intensity());
    volume_->raycast(K_, pose, maps_, p_.volume_stages);
    ref_.set_from_raycast(maps_, K_, pose, pyr_.levels(), p_.preprocess.pyramid_max_diff, photometric,
                          tracker_->reads_intensity());
  } else {
    ref_.set_from_frame(pyr_, pose);
  }
}

bool TrackingSession::keeps_keyframe(const FrameRecord& rec) {
  const float overlap = p_.tracker.keyframe_min_overlap;
  if (overlap <= 0.f || p_.tracker.mode != TrackingMode::frame_to_frame || !started_) return false;
  if (keyframe_inlier_ratio_ <= 0) {  // the keyframe's first frame: its ratio is the overlap's measure
    keyframe_inlier_ratio_ = rec.result.inlier_ratio;
    return true;
  }
  if (rec.result.inlier_ratio >= overlap * keyframe_inlier_ratio_) return true;
  keyframe_inlier_ratio_ = 0;  // this frame is the next keyframe
  return false;
}

void TrackingSession::accept(const RgbdFrame& frame, const SE3& pose, FrameRecord& rec) {
  if (volume_) {
    join_colour();
    volume_->integrate(depth_, rgb_, K_, pose, p_.volume_stages);
    rec.fused = true;
  }
  marks_.mark(kFused);
  if (tracker_ && !keeps_keyframe(rec)) update_reference(pose);
  if (odometry_) last_good_frame_ = host_copy(frame);
  // After lost frames the motion since prev_good_ spans all of them: no velocity to extrapolate.
  prev_good_ = started_ && lost_run_ == 0 ? last_good_ : pose;
  last_good_ = pose;
  last_good_time_ = frame.timestamp;
}

void TrackingSession::first_frame(const RgbdFrame& frame, FrameRecord& rec) {
  if (given_poses_) {  // the world is the given trajectory's: no gravity alignment of our own
    rec.result = given_pose(frame);
    return;
  }
  gravity_ = estimate_gravity(p_.tracker, frame.accelerometer, pyr_);
  if (p_.tracker.gravity != GravitySource::none && !gravity_.found)
    spdlog::warn("tracker.gravity: {} gave no gravity direction; the world frame is the first camera's",
                 enum_name(p_.tracker.gravity));
  SE3 world_T_first = gravity_.found ? gravity_aligned_pose(gravity_.down) : SE3::identity();
  if (frame.ground_truth) world_T_gt_ = world_T_first * frame.ground_truth->inverse();
  rec.result.world_T_camera = world_T_first;
  rec.result.status = TrackStatus::ok;  // the first frame defines the world
  rec.result.inlier_ratio = 1.0;
}

TrackResult TrackingSession::track_frame(const RgbdFrame& frame) {
  TrackResult r;
  r.world_T_camera = last_good_;
  if (p_.tracker.kind == "ground_truth") {
    if (frame.ground_truth) {
      r.world_T_camera = world_T_gt_ * *frame.ground_truth;
      r.status = TrackStatus::ok;
      r.inlier_ratio = 1.0;
    }
    return r;  // no ground truth for this frame: reported as no_reference
  }
  if (given_poses_) return given_pose(frame);
  if (odometry_) return track_external(frame);
  if (lost_run_ > 0) return relocalise(frame);
  // KinectFusion starts from the last pose; a constant-velocity prediction helps fast motion.
  SE3 initial = p_.tracker.constant_velocity ? last_good_ * last_motion(1) : last_good_;
  r = tracker_->track(pyr_, ref_, initial);
  if (p_.tracker.constant_velocity && !r.ok()) {
    // The motion model may have overshot (the camera stopped): retry from the last pose.
    TrackResult r2 = tracker_->track(pyr_, ref_, last_good_);
    if (r2.ok()) r = r2;
  }
  check_cut(r);
  if (r.ok()) last_inlier_ratio_ = r.inlier_ratio;
  return r;
}

namespace {
// The pose of `tr` at time t: a sample within 10 us of t is t's own (TUM files print 6 decimals,
// so a frame's time written and read back may differ from the frame's in the last digit: the
// last frame would otherwise fall after the last sample), else interpolate_pose's.
std::optional<TumPose> pose_at(const Trajectory& tr, double t, double max_gap) {
  constexpr double kSameTime = 1e-5;
  auto it = std::lower_bound(tr.begin(), tr.end(), t, [](const TumPose& p, double v) { return p.timestamp < v; });
  if (it != tr.end() && it->timestamp - t <= kSameTime) return *it;
  if (it != tr.begin() && t - (it - 1)->timestamp <= kSameTime) return *(it - 1);
  return interpolate_pose(tr, t, max_gap);
}
}  // namespace

// The given pose of the frame: params.frame_poses' by order, else the file's at the frame's time,
// matched as TUM ground truth is (interpolated between samples at most
// tracker.trajectory_max_gap apart). Without one the frame is reported as no_reference and not
// fused, like a ground-truth frame without ground truth.
TrackResult TrackingSession::given_pose(const RgbdFrame& frame) const {
  TrackResult r;
  r.world_T_camera = last_good_;
  std::optional<SE3> pose;
  if (p_.frame_poses) {
    if (processed_ < static_cast<std::int64_t>(p_.frame_poses->size())) pose = (*p_.frame_poses)[processed_];
  } else if (std::optional<TumPose> p = pose_at(*given_, frame.timestamp, p_.tracker.trajectory_max_gap)) {
    pose = p->se3();
  }
  if (pose) {
    r.world_T_camera = *pose;
    r.status = TrackStatus::ok;
    r.inlier_ratio = 1.0;
  }
  return r;
}

// The overlap of consecutive views changes gradually with motion; a sudden collapse of the inlier
// ratio means the view changed place (a cut), even if some floor or wall still fits.
void TrackingSession::check_cut(TrackResult& r) const {
  if (r.ok() && r.inlier_ratio < p_.tracker.min_inlier_ratio_vs_last * last_inlier_ratio_)
    r.status = TrackStatus::too_few_inliers;
}

SE3 TrackingSession::last_motion(std::int64_t frames) const {
  const SE3 step = prev_good_.inverse() * last_good_;
  SE3 m = SE3::identity();
  for (std::int64_t i = 0; i < frames; ++i) m = m * step;
  return m;
}

namespace {
// Relocalisation extrapolates the last motion over at most this many frames (half a second at 30 Hz).
constexpr std::int64_t kMaxExtrapolatedFrames = 15;
}  // namespace

// Frames tracked after lost ones (lost_run_ of them since the last good frame): the camera is
// searched for where it was (a covered camera held still) and where its last motion, repeated for
// every frame since, took it (one that kept turning: fr1_rpy turns 2.6 degrees a frame, 15 degrees
// over a 5-frame gap, beyond the basin of ICP from the old pose). Motion is extrapolated over at
// most half a second, beyond which a hand's motion is no longer predictable. Each estimate must
// pass check_relocalisation; the one that fits the model best is kept.
TrackResult TrackingSession::relocalise(const RgbdFrame& frame) {
  std::vector<SE3> guesses{last_good_};
  const SE3 step = last_motion(1);
  const bool moving = length(step.t) > 0 || rotation_angle_deg(step.R) > 0;
  if (moving && lost_run_ + 1 <= kMaxExtrapolatedFrames) guesses.push_back(last_good_ * last_motion(lost_run_ + 1));
  TrackResult best;
  for (std::size_t i = 0; i < guesses.size(); ++i) {
    TrackResult r = tracker_->track(pyr_, ref_, guesses[i]);
    check_cut(r);
    if (r.ok()) check_relocalisation(frame, r);
    const bool better = r.ok() != best.ok() ? r.ok() : r.residual_rms < best.residual_rms;
    if (i == 0 || better) best = r;
  }
  if (best.ok()) last_inlier_ratio_ = best.inlier_ratio;
  return best;
}

// After lost frames the tracker searches from the last good pose against the last good view, and
// may settle in a wrong minimum that still passes the per-frame tests: five covered frames of
// fr1_rpy were followed by a 23 cm / 11 degree "recovery" marked ok while the camera had moved
// 1.6 cm, and every later frame was offset. Two independent tests reject such a frame
// (it is then lost like the others, and the next frame tries again):
// - the pose moved no farther from the last good one than a handheld camera can in the time lost
//   (tracker.relocalise_max_speed / _angular_speed_deg, TrackerParams says why those speeds);
// - the frame fits the model about as well as the good frames did: a wrong minimum leaves
//   residuals near the correspondence threshold, a right one at the sensor's noise, so its RMS
//   residual may be at most relocalise_max_residual_ratio times the median of the recent good
//   frames' (2: twice the noise level; the false recovery above had 4 times).
void TrackingSession::check_relocalisation(const RgbdFrame& frame, TrackResult& r) const {
  // The margins cover the tracking error of the last good pose and of this one: a few millimetres
  // and a fraction of a degree a frame on freiburg1 (docs/TRACKING.md), five times over.
  constexpr double kMarginM = 0.02, kMarginDeg = 2.0;
  constexpr double kFrameRate = 30.0;  // timestamps that do not advance: the Kinect's rate is assumed
  double elapsed = frame.timestamp - last_good_time_;
  if (!(elapsed > 0)) elapsed = static_cast<double>(lost_run_ + 1) / kFrameRate;
  const SE3 jump = last_good_.inverse() * r.world_T_camera;
  const bool too_far = length(jump.t) > p_.tracker.relocalise_max_speed * elapsed + kMarginM ||
                       rotation_angle_deg(jump.R) > p_.tracker.relocalise_max_angular_speed_deg * elapsed + kMarginDeg;
  const double typical = good_residuals_.empty() ? 0.0 : median(good_residuals_);
  const bool misfit = p_.tracker.relocalise_max_residual_ratio > 0 && typical > 0 && std::isfinite(r.residual_rms) &&
                      r.residual_rms > p_.tracker.relocalise_max_residual_ratio * typical;
  if (too_far || misfit) r.status = TrackStatus::relocalisation_rejected;
}

// The relative pose of an external library, chained onto the last good pose. The prediction is
// ours (the last motion when tracker.constant_velocity, else none), a failure retries without it
// like our tracker does, and the same jump test applies; what the library does not report stays
// NaN or 0 in the statistics.
TrackResult TrackingSession::track_external(const RgbdFrame& frame) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  TrackResult r;
  r.world_T_camera = last_good_;
  r.residual_rms = r.inlier_ratio = r.condition = nan;
  std::optional<SE3> guess;
  if (lost_run_ > 0 && lost_run_ + 1 <= kMaxExtrapolatedFrames)
    guess = last_motion(lost_run_ + 1);  // where the last motion took it, then where it was (relocalise())
  else if (p_.tracker.constant_velocity) guess = last_motion(1);
  std::optional<external::OdometryEstimate> e = odometry_->prev_T_cur(last_good_frame_, frame, guess);
  if (!e && guess) {
    guess.reset();
    e = odometry_->prev_T_cur(last_good_frame_, frame, guess);
  }
  if (!e) {
    r.status = TrackStatus::degenerate;  // the library found no solution (it does not say why)
    return r;
  }
  r.world_T_camera = external::make_rigid(last_good_ * e->prev_T_cur);  // float products drift off SO(3)
  r.residual_rms = e->residual_rms;
  r.inlier_ratio = e->inlier_ratio;
  r.inliers = e->inliers;
  r.iterations = e->iterations;
  SE3 jump = (last_good_ * guess.value_or(SE3::identity())).inverse() * r.world_T_camera;
  r.translation_jump = length(jump.t);
  r.rotation_jump_deg = rotation_angle_deg(jump.R);
  bool implausible =
      r.translation_jump > p_.tracker.max_translation_jump || r.rotation_jump_deg > p_.tracker.max_rotation_jump_deg;
  r.status = implausible ? TrackStatus::implausible_jump : TrackStatus::ok;
  if (r.ok() && lost_run_ > 0) check_relocalisation(frame, r);
  return r;
}

// Stage times come from marks on the device's timeline, read once at the end: waiting after each
// stage would leave the GPU idle while the host queues the next one.
FrameRecord TrackingSession::process(const RgbdFrame& frame) {
  FrameRecord rec;
  rec.frame = frame.index;
  rec.timestamp = frame.timestamp;
  kept_ = false;
  marks_.mark(kStart);
  // External trackers read the host frame; our pyramid is needed only for the floor-plane gravity
  // of the first frame and for a volume to fuse into.
  const bool pyramid = !odometry_ || !started_ || volume_;
  if (pyramid) upload(frame);
  marks_.mark(kUploaded);
  if (pyramid) preprocess();
  marks_.mark(kPreprocessed);
  const bool tracked = started_;
  const ReferenceMaps* dyn_model = nullptr;
  bool masked = false;  // this frame has a dynamic mask
  if (!started_) {
    first_frame(frame, rec);
  } else {
    if (p_.dynamic.enabled) dyn_model = mask_before_tracking();
    if (p_.dynamic.enabled) marks_.mark(kMasked);
    rec.result = track_frame(frame);
    if (p_.dynamic.enabled) marks_.mark(kPosed);
  }
  if (dyn_model && rec.result.ok()) {
    // The mask at the tracked pose is the frame's: fusion skips it, the next frame's filter reads it.
    find_dynamic(*dyn_model, rec.result.world_T_camera, true);
    // The next frame's temporal support is what this frame kept, not the mask grown from it: the
    // grown border reaches static neighbours at the mover's depth, which are then never fused and,
    // from the mask, would support themselves frame after frame (a line left on the desk's edge).
    // The copies go on the kernels' stream (ordered after this frame's kernels, before the next
    // frame's) ahead of the count below, whose read-back waits for the GPU.
    dyn_prev_.buffer().copy_from_async(dyn_kept_.buffer());
    if (p_.dynamic.free_space_evidence == FreeSpaceEvidence::views) {
      if (dyn_prev_depth_.width() != K_.width) dyn_prev_depth_ = Image<float>(K_.width, K_.height, device_);
      dyn_prev_depth_.buffer().copy_from_async(pyr_.level(0).depth.buffer());
      dyn_prev_pose_ = rec.result.world_T_camera;
    }
    if (p_.dynamic.static_after_frames > 0) {
      std::swap(dyn_prev_age_, dyn_age_);  // the next frame's previous ages and anchors
      std::swap(dyn_prev_anchor_, dyn_anchor_);
      dyn_prev_pose_ = rec.result.world_T_camera;
    }
    with_exec(device_, [&]<class E>(const E& ex) {
      kernels::Dynamic<E>::mask_depth(ex, dyn_mask_.cview(), depth_.view());
      rec.dynamic_fraction = static_cast<double>(kernels::Dynamic<E>::count_dynamic(ex, dyn_mask_.cview())) /
                             static_cast<double>(K_.width * K_.height);
    });
    masked = true;
  } else if (p_.dynamic.enabled) {
    rec.dynamic_fraction = 0;  // the first frame, or a lost one: nothing masked, nothing fused
  }
  if (p_.dynamic.enabled && p_.dynamic.free_space_evidence == FreeSpaceEvidence::views && rec.result.ok())
    remember_view(rec.result.world_T_camera);  // an asynchronous copy every evidence_view_interval frames
  marks_.mark(kTracked);
  if (rec.result.ok()) {
    if (lost_run_ > 0 && !given_poses_)
      spdlog::info("frame {}: relocalised after {} lost frames, {:.3f} m / {:.1f} deg from the last good pose",
                   frame.index, lost_run_, length((last_good_.inverse() * rec.result.world_T_camera).t),
                   rotation_angle_deg((last_good_.inverse() * rec.result.world_T_camera).R));
    accept(frame, rec.result.world_T_camera, rec);
    lost_run_ = 0;
    // The relocalisation test's reference: residuals of frames tracked against the model (the
    // first frame has none; external trackers may report NaN).
    if (tracked && rec.result.residual_rms > 0 && std::isfinite(rec.result.residual_rms)) {
      if (good_residuals_.size() == 10) good_residuals_.erase(good_residuals_.begin());
      good_residuals_.push_back(rec.result.residual_rms);
    }
  } else {
    ++lost_;
    ++lost_run_;
    rec.result.world_T_camera = last_good_;  // the estimate was not trusted: keep the last good pose
  }
  started_ = true;
  ++processed_;
  join_colour();  // a lost frame's colour copy too: the caller may reuse the frame after we return
  marks_.mark(kEnd);
  rec.preprocess_ms = marks_.ms(kStart, kPreprocessed);
  rec.upload_ms = marks_.ms(kStart, kUploaded);
  if (tracked) rec.track_ms = marks_.ms(kPreprocessed, kTracked);
  if (tracked && p_.dynamic.enabled) rec.dynamic_ms = marks_.ms(kPreprocessed, kMasked) + marks_.ms(kPosed, kTracked);
  if (rec.result.ok()) {  // accept() ran: fusion and the next reference
    rec.fuse_ms = marks_.ms(kTracked, kEnd);
    rec.raycast_ms = marks_.ms(kFused, kEnd);
  }
  rec.frame_ms = marks_.ms(kStart, kEnd);
  if (p_.volume_stages) {
    const std::size_t first_row = p_.volume_stages->rows().size();
    p_.volume_stages->end_frame(rec.frame);
    rec.allocate_ms = volume_allocate_ms(first_row);
  }
  // The mask against the movers' ground truth (synthetic movers), after the frame's last mark:
  // its downloads are in no stage's time.
  if (masked && frame.movers && frame.ground_truth && frame.mover_mask.width() == dyn_mask_.width() &&
      frame.mover_mask.height() == dyn_mask_.height())
    rec.mask_score = score_mask(frame.mover_mask.to_host(), dyn_mask_.to_host(), *frame.movers, frame.ground_truth->t);
  return rec;
}

void TrackingSession::correct(const SE3& delta) {
  last_good_ = delta * last_good_;
  prev_good_ = delta * prev_good_;
  ref_.move_world(delta);
}

// Allocation as Niessner et al. (2013, section 4) count it: inserting the frame's blocks and listing
// the visible ones (every pass, when a full table or pool made the volume grow and repeat them).
double TrackingSession::volume_allocate_ms(std::size_t first_row) const {
  double ms = 0;
  const auto& rows = p_.volume_stages->rows();
  for (std::size_t i = first_row; i < rows.size(); ++i)
    if (rows[i].stage == "allocate" || rows[i].stage == "visible") ms += rows[i].ms;
  return ms;
}

}  // namespace seamless
