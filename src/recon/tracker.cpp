#include "recon/tracker.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/preprocess.hpp"
#include "kernels/recon/rgbd.hpp"
#include "recon/volume.hpp"

namespace seamless {

namespace {
constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d to_eigen(const mat3& R) {
  Eigen::Matrix3d M;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) M(r, c) = R.m[r][c];
  return M;
}
}  // namespace

const char* to_string(TrackStatus s) {
  switch (s) {
    case TrackStatus::ok: return "ok";
    case TrackStatus::too_few_inliers: return "too_few_inliers";
    case TrackStatus::implausible_jump: return "implausible_jump";
    case TrackStatus::degenerate: return "degenerate";
    case TrackStatus::no_reference: return "no_reference";
    case TrackStatus::relocalisation_rejected: return "relocalisation_rejected";
  }
  return "?";
}

// ---- ReferenceMaps ------------------------------------------------------------------------------

void ReferenceMaps::resize(const Intrinsics& K, int levels, Device d, bool intensity) {
  bool same = static_cast<int>(levels_.size()) == levels && !levels_.empty() && levels_[0].vertices.device() == d &&
              levels_[0].K.width == K.width && levels_[0].K.height == K.height && has_intensity() == intensity;
  if (!same) {
    levels_.clear();
    for (int l = 0; l < levels; ++l) {
      Intrinsics k = K.level(l);
      levels_.push_back({k, Image<vec3>(k.width, k.height, d), Image<vec3>(k.width, k.height, d),
                         intensity ? Image<float>(k.width, k.height, d) : Image<float>()});
    }
  }
  for (int l = 0; l < levels; ++l) levels_[l].K = K.level(l);
}

void ReferenceMaps::set_from_frame(const FramePyramid& frame, const SE3& world_T_camera) {
  const PyramidLevel& l0 = frame.level(0);
  bool intensity = l0.intensity.width() > 0;
  resize(l0.K, frame.levels(), frame.device(), intensity);
  for (int l = 0; l < frame.levels(); ++l) {
    levels_[l].vertices.buffer().copy_from(frame.level(l).vertices.buffer());
    levels_[l].normals.buffer().copy_from(frame.level(l).normals.buffer());
    if (intensity) levels_[l].intensity.buffer().copy_from(frame.level(l).intensity.buffer());
  }
  world_T_ref_ = world_T_camera;
}

bool ReferenceMaps::reads_model_colour(const Intrinsics& K, int levels, const FramePyramid* photometric,
                                       bool with_intensity) {
  const bool frame =
      photometric && photometric->level(0).intensity.width() == K.width && photometric->levels() >= levels;
  return with_intensity && !frame;
}

void ReferenceMaps::set_from_raycast(const RaycastMaps& maps, const Intrinsics& K, const SE3& world_T_camera,
                                     int levels, float max_diff, const FramePyramid* photometric, bool with_intensity) {
  if (maps.vertex.width() != K.width || maps.vertex.height() != K.height)
    throw Error("raycast maps are " + std::to_string(maps.vertex.width()) + "x" + std::to_string(maps.vertex.height()) +
                " but the tracker's intrinsics say " + std::to_string(K.width) + "x" + std::to_string(K.height));
  const bool model_colour = reads_model_colour(K, levels, photometric, with_intensity);
  const bool from_frame = with_intensity && !model_colour;
  const bool from_model = model_colour && maps.color.width() == K.width && maps.color.height() == K.height;
  const bool intensity = from_frame || from_model;
  Device d = maps.vertex.device();
  resize(K, levels, d, intensity);
  const SE3 camera_T_world = world_T_camera.inverse();
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::Icp<E>::transform_maps(ex, maps.vertex.cview(), maps.normal.cview(), camera_T_world,
                                    levels_[0].vertices.view(), levels_[0].normals.view());
    if (from_model) kernels::Rgbd<E>::rgb_to_intensity(ex, maps.color.cview(), levels_[0].intensity.view());
    for (int l = 1; l < levels; ++l) {
      kernels::Icp<E>::pyr_down_maps(ex, levels_[l - 1].vertices.cview(), levels_[l - 1].normals.cview(),
                                     levels_[l].vertices.view(), levels_[l].normals.view(), max_diff);
      if (from_model)
        kernels::Preprocess<E>::pyr_down_intensity(ex, levels_[l - 1].intensity.cview(), levels_[l].intensity.view());
    }
  });
  if (from_frame)
    for (int l = 0; l < levels; ++l) levels_[l].intensity.buffer().copy_from(photometric->level(l).intensity.buffer());
  world_T_ref_ = world_T_camera;
}

// ---- host side of a Gauss-Newton step -----------------------------------------------------------

IcpStep solve_icp_step(const kernels::IcpSums& s) {
  Eigen::Matrix<double, 6, 6> A;
  for (int i = 0, k = 0; i < 6; ++i)
    for (int j = i; j < 6; ++j) A(i, j) = A(j, i) = s.jtj[k++];
  IcpStep step;
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> eig(A, Eigen::EigenvaluesOnly);
  double lo = eig.eigenvalues()(0), hi = eig.eigenvalues()(5);
  step.condition = lo > 0 ? hi / lo : std::numeric_limits<double>::infinity();
  if (!(lo > 0) || !std::isfinite(step.condition)) return step;
  step.solved = kernels::solve_normal_equations(s, step.xi);  // the solve the device loop runs
  if (!step.solved) std::fill(step.xi, step.xi + 6, 0.0);
  return step;
}

SE3 se3_exp(const double xi[6]) {
  kernels::IcpPose p = kernels::to_icp_pose(SE3::identity());
  kernels::left_update(p, xi);
  return kernels::to_se3(p);
}

double rotation_angle_deg(const mat3& R) {
  double c = 0.5 * (R.m[0][0] + R.m[1][1] + R.m[2][2] - 1.0);
  return std::acos(std::max(-1.0, std::min(1.0, c))) * 180.0 / kPi;
}

namespace {
// Keeps a pose exactly rigid after many float compositions (nearest rotation by SVD).
SE3 orthonormalize(SE3 T) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(to_eigen(T.R), Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R.m[r][c] = static_cast<float>(R(r, c));
  return T;
}
}  // namespace

// ---- Tracker ------------------------------------------------------------------------------------

Tracker::Tracker(const TrackerParams& params, Device device) : params_(params), device_(device) {
  if (params_.kind != "icp" && params_.kind != "rgbd")
    throw ConfigError("tracker.kind '" + params_.kind +
                      "' is not an ICP tracker (the Tracker class runs icp and rgbd)");
}

bool Tracker::use_photometric(const FramePyramid& frame, const ReferenceMaps& ref) const {
  return reads_intensity() && ref.has_intensity() && frame.level(0).intensity.width() > 0;
}

bool Tracker::robust(const FramePyramid& frame, const ReferenceMaps& ref) const {
  return params_.weighting == RgbdWeighting::robust && use_photometric(frame, ref);
}

kernels::IcpState* Tracker::state() const {
  if (state_.size() != 1 || state_.device() != device_) state_ = Buffer<kernels::IcpState>(1, device_);
  return state_.data();
}

void Tracker::set_pose(const SE3& ref_T_cur) const {
  const kernels::IcpPose p = kernels::to_icp_pose(ref_T_cur);
  memory::copy(&state()->pose, device_, &p, Device::CPU, sizeof p);
}

kernels::IcpSums* Tracker::sums_slot(int level) const {
  if (level >= kernels::kIcpMaxLevels)
    throw ConfigError("the tracker handles at most " + std::to_string(kernels::kIcpMaxLevels) +
                      " pyramid levels, not " + std::to_string(level + 1) + " (preprocess.levels)");
  return &state()->sums[level];
}

void Tracker::reduce_into(const FramePyramid& frame, const ReferenceMaps& ref, int level, int steps) const {
  const PyramidLevel& cur = frame.level(level);
  const ReferenceLevel& rl = ref.level(level);
  kernels::IcpLevel L{cur.vertices.cview(),
                      cur.normals.cview(),
                      rl.vertices.cview(),
                      rl.normals.cview(),
                      rl.K,
                      SE3::identity(),
                      params_.dist_threshold,
                      static_cast<float>(std::cos(params_.angle_threshold_deg * kPi / 180.0)),
                      static_cast<float>(params_.stop_rotation_deg * kPi / 180.0),
                      params_.stop_translation};
  if (level < static_cast<int>(params_.pixel_stride.size())) L.stride = params_.pixel_stride[level];
  L.max_depth = params_.max_depth;
  kernels::IcpState* st = state();
  kernels::IcpSums* out = sums_slot(level);
  with_exec(device_, [&]<class E>(const E& ex) {
    if (!use_photometric(frame, ref)) {
      if (steps == 0) return kernels::Icp<E>::icp_reduce_into(ex, L, &st->pose, out);
      return kernels::Icp<E>::icp_level_steps(ex, L, &st->pose, out, steps);
    }
    kernels::RgbdLevel R{L,
                         cur.intensity.cview(),
                         rl.intensity.cview(),
                         1.f,
                         params_.photometric_weight,
                         params_.max_intensity_diff,
                         robust(frame, ref) ? params_.robust_dof : 0.f,
                         params_.depth_noise == DepthNoiseModel::depth_squared};
    R.photometric_all_visible = params_.photometric_pixels == PhotometricPixels::visible;
    R.min_gradient = params_.min_gradient;
    if (rgbd_sums_.size() != 1 || rgbd_sums_.device() != device_) rgbd_sums_ = Buffer<kernels::RgbdSums>(1, device_);
    if (steps == 0) return kernels::Rgbd<E>::rgbd_reduce_into(ex, R, &st->pose, rgbd_sums_.data(), out);
    kernels::Rgbd<E>::rgbd_level_steps(ex, R, &st->pose, rgbd_sums_.data(), out, steps);
  });
}

kernels::IcpSums Tracker::reduce(const FramePyramid& frame, const ReferenceMaps& ref, int level,
                                 const SE3& ref_T_cur) const {
  set_pose(ref_T_cur);
  // Robust weighting: a first reduction estimates the residual scales at this pose, so that the
  // system returned is weighted as the tracker's own steps are.
  if (robust(frame, ref)) reduce_into(frame, ref, level, 0);
  reduce_into(frame, ref, level, 0);
  kernels::IcpSums s;
  memory::copy(&s, Device::CPU, sums_slot(level), device_, sizeof s);
  return s;
}

// The whole coarse-to-fine loop is queued on the device, one launch per pyramid level (each
// holds the level's Gauss-Newton steps: reduce, solve, update, and the stop once converged); the
// host waits once, for the final estimate and the finest level's last system.
TrackResult Tracker::track(const FramePyramid& frame, const ReferenceMaps& ref,
                           const SE3& initial_world_T_camera) const {
  TrackResult r;
  r.world_T_camera = initial_world_T_camera;
  if (ref.empty()) return r;
  const int levels = std::min({frame.levels(), ref.levels(), static_cast<int>(params_.iterations.size())});
  set_pose(ref.world_T_ref().inverse() * initial_world_T_camera);  // also clears the residual scales
  // Robust weighting: one scale-only reduction at the coarsest level first (no step), so that the
  // first step is already balanced; the scales then follow every step (kernels/recon/rgbd.hpp).
  if (levels > 0 && robust(frame, ref)) reduce_into(frame, ref, levels - 1, 0);
  for (int l = levels - 1; l >= 0; --l)
    if (params_.iterations[l] > 0) reduce_into(frame, ref, l, params_.iterations[l]);
  kernels::IcpState st;  // one copy back, which waits for the loop
  memory::copy(&st, Device::CPU, state(), device_, sizeof st);
  const kernels::IcpPose& pose = st.pose;
  r.iterations = pose.steps;
  bool degenerate = false;
  if (levels > 0 && params_.iterations[0] > 0) {  // statistics of the finest level's last system
    const kernels::IcpSums& s = st.sums[0];       // the last system summed (a done level stops there)
    IcpStep step = solve_icp_step(s);
    r.inliers = static_cast<std::int64_t>(s.inliers);
    r.inlier_ratio = s.valid > 0 ? s.inliers / s.valid : 0.0;
    r.residual_rms = s.inliers > 0 ? std::sqrt(s.error / s.inliers) : 0.0;
    r.condition = step.condition;
    degenerate = !step.solved;
  }
  r.world_T_camera = ref.world_T_ref() * orthonormalize(kernels::to_se3(pose));
  r.status = degenerate ? TrackStatus::degenerate : TrackStatus::ok;
  check_loss(r, initial_world_T_camera);
  return r;
}

void Tracker::check_loss(TrackResult& r, const SE3& initial) const {
  SE3 delta = initial.inverse() * r.world_T_camera;
  r.translation_jump = length(delta.t);
  r.rotation_jump_deg = rotation_angle_deg(delta.R);
  if (r.status != TrackStatus::ok) return;
  if (r.inlier_ratio < params_.min_inlier_ratio) r.status = TrackStatus::too_few_inliers;
  else if (!(r.condition <= params_.max_condition)) r.status = TrackStatus::degenerate;
  else if (r.translation_jump > params_.max_translation_jump || r.rotation_jump_deg > params_.max_rotation_jump_deg)
    r.status = TrackStatus::implausible_jump;
}

}  // namespace seamless
