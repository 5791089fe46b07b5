#include "io/synthetic_source.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/movers.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless {
namespace {

// Deterministic phase in [0, 2 pi) for wobble component k.
double phase(std::uint64_t seed, int k) {
  std::uint32_t h =
      kernels::hash32(static_cast<std::uint32_t>(seed) ^
                      kernels::hash32(static_cast<std::uint32_t>(k + 1) ^ static_cast<std::uint32_t>(seed >> 32)));
  return 2 * std::numbers::pi * (h / 4294967296.0);
}

// A smooth wobble: three sinusoids at incommensurate frequencies (Hz), like a hand that drifts.
double wobble(std::uint64_t seed, int axis, double t) {
  const double f[3] = {0.23, 0.61, 1.37}, a[3] = {1.0, 0.45, 0.15};
  double s = 0;
  for (int k = 0; k < 3; ++k) s += a[k] * std::sin(2 * std::numbers::pi * f[k] * t + phase(seed, 3 * axis + k));
  return s / 1.6;  // |s| <= 1
}

vec3 fv(double x, double y, double z) { return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)}; }

// Camera looking from eye at target, z forward, y down (image rows), world z up; rolled by `roll`.
SE3 look_at(vec3 eye, vec3 target, float roll) {
  vec3 z = normalize(target - eye);
  vec3 x = normalize(cross(z, vec3{0.f, 0.f, 1.f}));
  vec3 y = cross(z, x);
  float c = std::cos(roll), s = std::sin(roll);
  vec3 xr = x * c + y * s, yr = y * c - x * s;
  SE3 T;
  T.R = {{{xr.x, yr.x, z.x}, {xr.y, yr.y, z.y}, {xr.z, yr.z, z.z}}};
  T.t = eye;
  return T;
}

}  // namespace

namespace {

struct PathPoint {
  double eye[3], target[3], roll;
};

// The path in double precision (the accelerometer differentiates it twice).
PathPoint path_point(const SyntheticParams& p, double t) {
  const vec3 c = kernels::room::desk_centre();
  double shake = p.shake;
  double ang = (p.start_deg + (p.trajectory == CameraPath::orbit ? p.speed_deg * t : 0.0)) * std::numbers::pi / 180.0;
  double r = p.radius + 0.05 * shake * wobble(p.seed, 0, t);
  // Amplitudes: a few centimetres and a degree or two, what a steady hand-held camera does.
  return {{c.x + r * std::cos(ang), c.y + r * std::sin(ang), p.height + 0.04 * shake * wobble(p.seed, 1, t)},
          {c.x + 0.05 * shake * wobble(p.seed, 2, t), c.y + 0.05 * shake * wobble(p.seed, 3, t),
           c.z + 0.03 * shake * wobble(p.seed, 4, t)},
          0.035 * shake * wobble(p.seed, 5, t)};
}

}  // namespace

SE3 synthetic_camera_pose(const SyntheticParams& p, double t) {
  PathPoint q = path_point(p, t);
  return look_at(fv(q.eye[0], q.eye[1], q.eye[2]), fv(q.target[0], q.target[1], q.target[2]),
                 static_cast<float>(q.roll));
}

vec3 synthetic_accelerometer(const SyntheticParams& p, double t) {
  const double h = 1e-3;
  PathPoint a = path_point(p, t - h), b = path_point(p, t), c = path_point(p, t + h);
  vec3 acc = fv((a.eye[0] - 2 * b.eye[0] + c.eye[0]) / (h * h), (a.eye[1] - 2 * b.eye[1] + c.eye[1]) / (h * h),
                (a.eye[2] - 2 * b.eye[2] + c.eye[2]) / (h * h));
  SE3 T = synthetic_camera_pose(p, t);
  return transpose(T.R) * (acc - kernels::room::gravity());
}

kernels::DepthNoise synthetic_noise_model(const SyntheticParams& p) {
  kernels::DepthNoise n;
  n.enabled = p.noise;
  n.sigma_disparity = p.sensor.sigma_disparity;
  n.min_depth = p.sensor.min_depth;
  n.max_depth = p.sensor.max_depth;
  n.min_incidence_cos = static_cast<float>(std::cos(p.sensor.max_incidence_deg * std::numbers::pi / 180.0));
  n.edge_jump = p.sensor.edge_jump;
  n.projector_shadow = p.sensor.projector_shadow;
  return n;
}

SyntheticSource::SyntheticSource(const InputParams& params, Device device)
    : p_(params.synthetic), device_(device), first_(params.first_frame) {
  // A negative focal length gives the flipped (positive) camera: the room is rendered as the
  // flipped images of a recorded folder would show it.
  K_ = resolve_intrinsics(params.intrinsics).K;
  for (float& d : K_.dist) d = 0.f;  // an ideal pinhole: the room is rendered undistorted
  count_ = std::max<std::int64_t>(0, p_.frames - first_);
  if (params.max_frames > 0) count_ = std::min(count_, params.max_frames);
  scratch_ = Image<float>(K_.width, K_.height, device_);
  depth_dev_ = Image<float>(K_.width, K_.height, device_);
  rgb_dev_ = Image<uchar3>(K_.width, K_.height, device_);
}

void SyntheticSource::render(const SE3& T, std::uint32_t frame_number, Image<float>& depth, Image<uchar3>& rgb) {
  Image<std::uint8_t> mask;
  render(T, frame_number, depth, rgb, mask);
}

void SyntheticSource::render(const SE3& T, std::uint32_t frame_number, Image<float>& depth, Image<uchar3>& rgb,
                             Image<std::uint8_t>& mask) {
  render(T, frame_number, pose_movers(p_.movers, frame_number / p_.fps), depth, rgb, mask);
}

void SyntheticSource::render(const SE3& T, std::uint32_t frame_number, const kernels::movers::Scene& movers,
                             Image<float>& depth, Image<uchar3>& rgb, Image<std::uint8_t>& mask) {
  kernels::DepthNoise noise = synthetic_noise_model(p_);
  std::uint32_t seed = static_cast<std::uint32_t>(p_.seed ^ (p_.seed >> 32));
  const bool with_mask = !p_.movers.empty();
  if (with_mask && mask_dev_.width() != K_.width) mask_dev_ = Image<std::uint8_t>(K_.width, K_.height, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::RenderRoom<E>::render_room(ex, K_, T, noise, seed, frame_number, movers, scratch_.view(),
                                        depth_dev_.view(), rgb_dev_.view(),
                                        with_mask ? mask_dev_.view() : View2D<std::uint8_t>{});
    ex.synchronize();
  });
  depth.buffer().copy_from(depth_dev_.buffer());
  rgb.buffer().copy_from(rgb_dev_.buffer());
  if (!with_mask) {
    mask = Image<std::uint8_t>();
    return;
  }
  if (mask.width() != K_.width || mask.height() != K_.height)
    mask = Image<std::uint8_t>(K_.width, K_.height, Device::CPU);
  mask.buffer().copy_from(mask_dev_.buffer());
}

bool SyntheticSource::next(RgbdFrame& frame) {
  if (next_ >= count_) return false;
  std::int64_t k = first_ + next_;
  double t = k / p_.fps;
  SE3 T = synthetic_camera_pose(p_, t);
  reserve_frame_images(frame, K_.width, K_.height, device_ == Device::CUDA);
  const kernels::movers::Scene movers = pose_movers(p_.movers, t);  // posed once: rendered and reported
  render(T, static_cast<std::uint32_t>(k), movers, frame.depth, frame.rgb, frame.mover_mask);
  if (!p_.movers.empty()) frame.movers = movers;
  frame.index = next_++;
  frame.timestamp = t;
  frame.intrinsics = K_;
  frame.accelerometer = synthetic_accelerometer(p_, t);
  frame.ground_truth = T;
  return true;
}

}  // namespace seamless
