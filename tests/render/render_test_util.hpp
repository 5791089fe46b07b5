// Shared helpers of the render tests: skip without EGL, small pixel accessors, simple meshes.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/math.hpp"
#include "recon/volume.hpp"
#include "render/renderer.hpp"

namespace seamless::test {

// GTEST_SKIP unless a headless EGL context can be created (Mesa in CI).
#define SEAMLESS_REQUIRE_EGL()                                          \
  do {                                                                  \
    std::string why_;                                                   \
    if (!::seamless::HeadlessContext::available(&why_))                 \
      GTEST_SKIP() << "no EGL display could be created here: " << why_; \
  } while (0)

struct Pixels {
  std::vector<uchar3> px;
  int w = 0, h = 0;
  explicit Pixels(const Image<uchar3>& im) : px(im.to_host()), w(im.width()), h(im.height()) {}
  uchar3 at(int u, int v) const { return px[static_cast<std::size_t>(v) * w + u]; }
};

inline bool same(uchar3 a, uchar3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }
inline int max_diff(uchar3 a, uchar3 b) {
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
}
// sRGB level -> linear (IEC 61966-2-1), as the renderer's color.glsl.
inline float linear(std::uint8_t c) {
  const float x = c / 255.f;
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
}
inline uchar3 to_rgb8(vec3 c) {
  auto q = [](float f) { return static_cast<std::uint8_t>(std::lround(std::clamp(f, 0.f, 1.f) * 255.f)); };
  return {q(c.x), q(c.y), q(c.z)};
}

// A flat rectangle [x0, x1] x [y0, y1] at depth z (world = camera frame for an identity pose),
// one colour, normals facing the camera (-z).
Mesh rectangle(float x0, float x1, float y0, float y1, float z, uchar3 color);
// The form factor from a point p (unit normal n) to an axis-aligned box (centre, half extents), by
// the area integral over the faces p sees: F = sum over faces of the integral of
// max(cos(theta_p), 0) cos(theta_face) / (pi r^2) dA (what lies below p's plane does not count), by the
// midpoint rule on square cells of at most a quarter of p's distance d to the box (4 to 256 a side):
// its relative error is about (cell / d)^2 / 24, below 0.3 %. An independent check of the
// renderer's contour integral (occlusion.glsl).
double box_form_factor(vec3 p, vec3 n, vec3 centre, vec3 half);
// Pinhole intrinsics of a w x h image.
Intrinsics intrinsics(float f, float cx, float cy, int w, int h);
RenderCamera camera(const Intrinsics& K, const SE3& world_T_camera = SE3::identity());
// Rotation about an axis (radians).
mat3 rotation(vec3 axis, float angle);

}  // namespace seamless::test
