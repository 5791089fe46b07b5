// Renders the synthetic room (kernels/scene/synthetic_room.hpp) as a Kinect v1 would see it: exact
// ray-primitive intersection per pixel, then an optional sensor model.
//
// Sensor model (noise.enabled), after Khoshelham & Elberink 2012 ("Accuracy and resolution of
// Kinect depth data for indoor mapping applications", Sensors 12(2), eqs. 5-9) and Smisek,
// Jancosek & Pajdla 2011 ("3D with Kinect", ICCV workshops):
//   - the Kinect measures disparity d = f b / z (pixels; f focal length, b = 0.075 m baseline between
//     the IR projector and camera) with 1/8-pixel steps, so depth is quantised with a step that grows
//     with z^2: dz = z^2 (1/8) / (f b);  optional Gaussian disparity noise sigma_d gives
//     sigma_z = z^2 sigma_d / (f b) (Khoshelham eq. 9);
//   - no depth where the projector's pattern cannot reach (shadow of the baseline), at grazing
//     incidence, next to depth discontinuities (the correlation window straddles the edge), and
//     outside the working range [min_depth, max_depth].
// With noise off the depth is the exact z of the first surface along each pixel's ray.
#pragma once
#include <cstdint>

#include "core/intrinsics.hpp"
#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"
#include "kernels/scene/movers.hpp"

namespace seamless::kernels {

struct DepthNoise {
  bool enabled = false;
  float baseline = 0.075f;        // metres, Kinect v1 projector-camera baseline
  float disparity_step = 0.125f;  // pixels: 1/8 sub-pixel disparity steps
  float sigma_disparity = 0.f;    // pixels: extra Gaussian disparity noise (0 = quantisation only)
  float min_depth = 0.4f;         // metres: Kinect v1 working range
  float max_depth = 4.0f;
  float min_incidence_cos = 0.2f;  // cos of the largest incidence angle that still returns (~78 deg)
  float edge_jump = 0.05f;         // relative depth jump to a neighbour that counts as an edge
  bool projector_shadow = true;    // drop pixels the projector cannot see
};

// Counter-based random numbers (a pure function of its inputs, so both backends and any thread
// order draw the same values): the "lowbias32" integer hash (C. Wellons, 2018) chained over the keys.
SEAMLESS_HD inline std::uint32_t hash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}
// Uniform in (0, 1): never 0, so log() below is finite.
SEAMLESS_HD inline float hash_uniform(std::uint32_t seed, std::uint32_t frame, std::uint32_t pixel,
                                      std::uint32_t stream) {
  std::uint32_t h = hash32(seed ^ hash32(frame ^ hash32(pixel * 4u + stream)));
  return (static_cast<float>(h >> 8) + 0.5f) * (1.f / 16777216.f);
}
// Standard normal by Box-Muller from two of the uniforms above.
SEAMLESS_HD inline float hash_gauss(std::uint32_t seed, std::uint32_t frame, std::uint32_t pixel) {
  float u1 = hash_uniform(seed, frame, pixel, 0), u2 = hash_uniform(seed, frame, pixel, 1);
  return sqrtf(-2.f * logf(u1)) * cosf(6.2831853f * u2);
}

// Depth as the Kinect reports it: disparity f b / z (plus noise), rounded to the disparity step,
// converted back. 0 when the disparity falls to zero or below (beyond the sensor's reach).
SEAMLESS_HD inline float kinect_quantise(float z, float f, const DepthNoise& n, float gauss) {
  float fb = f * n.baseline;
  float d = fb / z + n.sigma_disparity * gauss;
  float dq = roundf(d / n.disparity_step) * n.disparity_step;
  return dq > 0.f ? fb / dq : 0.f;
}

template <Executor Exec> struct RenderRoom {
  // depth (metres, 0 = none) and rgb of the room seen from world_T_camera through the pinhole K,
  // with the frame's movers (people, balls) in it. scratch is a float image of the same size (holds
  // the noise-free depth between the two passes). mask (optional: an empty view skips it) gets the
  // id of the mover each pixel sees (0: the static room or nothing): the ground truth of dynamic
  // pixels. The noise is a pure function of (seed, frame, pixel): deterministic on both backends.
  static void render_room(const Exec& ex, Intrinsics K, SE3 world_T_camera, DepthNoise noise, std::uint32_t seed,
                          std::uint32_t frame, const movers::Scene& movers, View2D<float> scratch, View2D<float> depth,
                          View2D<uchar3> rgb, View2D<std::uint8_t> mask);
};

}  // namespace seamless::kernels
