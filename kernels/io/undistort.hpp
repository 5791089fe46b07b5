// Lens undistortion of input images (Brown-Conrady model, OpenCV coefficient order k1 k2 p1 p2 k3,
// as published with the TUM RGB-D calibrations). The output is the ideal pinhole image with the
// same fx fy cx cy: each output pixel looks up where the lens put it.
#pragma once
#include "core/intrinsics.hpp"
#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// Where the lens images the ray through undistorted pixel (x, y) (Brown 1966; OpenCV's model).
SEAMLESS_HD inline vec2 distort_pixel(const Intrinsics& K, float x, float y) {
  float xn = (x - K.cx) / K.fx, yn = (y - K.cy) / K.fy;
  float k1 = K.dist[0], k2 = K.dist[1], p1 = K.dist[2], p2 = K.dist[3], k3 = K.dist[4];
  float r2 = xn * xn + yn * yn;
  float radial = 1.f + r2 * (k1 + r2 * (k2 + r2 * k3));
  float xd = xn * radial + 2.f * p1 * xn * yn + p2 * (r2 + 2.f * xn * xn);
  float yd = yn * radial + p1 * (r2 + 2.f * yn * yn) + 2.f * p2 * xn * yn;
  return {K.fx * xd + K.cx, K.fy * yd + K.cy};
}

template <Executor Exec> struct Undistort {
  // map(x, y) = distort_pixel(K, x, y) for every output pixel: computed once per camera.
  static void undistort_map(const Exec& ex, Intrinsics K, View2D<vec2> map);

  // Depth: nearest neighbour (interpolating would invent depths across discontinuities).
  static void remap_depth(const Exec& ex, View2D<const vec2> map, View2D<const float> in, View2D<float> out);

  // Colour: bilinear.
  static void remap_rgb(const Exec& ex, View2D<const vec2> map, View2D<const uchar3> in, View2D<uchar3> out);
};

}  // namespace seamless::kernels
