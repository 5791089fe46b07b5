// The built-in synthetic room as a frame source: the analytic scene of kernels/scene/synthetic_room.hpp
// seen along a smooth, deterministic, hand-held-like camera path, rendered by the kernel family
// kernels/io/render_room (exact depth, optional Kinect v1 sensor model). Ground truth is exact.
#pragma once
#include "core/buffer.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "kernels/io/render_room.hpp"

namespace seamless {

// world_T_camera at time t (seconds) of the path `p.trajectory`: the camera circles the desk at
// p.radius and p.height, looks at the desk centre, and wobbles like a hand-held camera (a sum of
// incommensurate sinusoids whose phases come from p.seed, scaled by p.shake). Smooth in t.
SE3 synthetic_camera_pose(const SyntheticParams& p, double t);

// What the accelerometer of a camera on that path reads at t: R^T (a - g), with the acceleration a
// from central differences of the path (h = 1 ms), in the camera frame.
vec3 synthetic_accelerometer(const SyntheticParams& p, double t);

// The sensor model of the config as the render kernel takes it.
kernels::DepthNoise synthetic_noise_model(const SyntheticParams& p);

class SyntheticSource : public FrameSource {
 public:
  SyntheticSource(const InputParams& params, Device device = Device::CPU);
  bool next(RgbdFrame& frame) override;
  std::optional<std::int64_t> size() const override { return count_; }
  std::string name() const override { return "synthetic room"; }
  Intrinsics intrinsics() const override { return K_; }

  // Renders one view (any pose) with this source's camera and sensor model into host images, with
  // the movers as they are at frame_number's time (mask: their ids, or empty when there are none).
  void render(const SE3& world_T_camera, std::uint32_t frame_number, Image<float>& depth, Image<uchar3>& rgb);
  void render(const SE3& world_T_camera, std::uint32_t frame_number, Image<float>& depth, Image<uchar3>& rgb,
              Image<std::uint8_t>& mask);

 private:
  void render(const SE3& world_T_camera, std::uint32_t frame_number, const kernels::movers::Scene& movers,
              Image<float>& depth, Image<uchar3>& rgb, Image<std::uint8_t>& mask);

 public:
 private:
  SyntheticParams p_;
  Intrinsics K_;
  Device device_;
  std::int64_t first_, count_, next_ = 0;
  Image<float> scratch_, depth_dev_;
  Image<uchar3> rgb_dev_;
  Image<std::uint8_t> mask_dev_;
};

}  // namespace seamless
