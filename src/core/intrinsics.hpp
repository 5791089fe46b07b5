// Pinhole camera intrinsics (Kinect v1 / TUM conventions: x right, y down, z forward, metres).
#pragma once
#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless {

struct Intrinsics {
  float fx = 525.f, fy = 525.f, cx = 319.5f, cy = 239.5f;
  int width = 640, height = 480;
  // Brown-Conrady radial/tangential coefficients k1 k2 p1 p2 k3 (OpenCV order). The kernels work on
  // undistorted pinhole images; the sources undistort on input when these are non-zero.
  float dist[5] = {0, 0, 0, 0, 0};

  SEAMLESS_HD vec3 unproject(float u, float v, float depth) const {
    return {(u - cx) * depth / fx, (v - cy) * depth / fy, depth};
  }
  SEAMLESS_HD vec2 project(vec3 p) const { return {fx * p.x / p.z + cx, fy * p.y / p.z + cy}; }
  // Intrinsics of pyramid level `level` (each level halves the resolution; pixel centres move).
  SEAMLESS_HD Intrinsics level(int lvl) const {
    Intrinsics k = *this;
    for (int i = 0; i < lvl; ++i) {
      k.fx *= 0.5f;
      k.fy *= 0.5f;
      k.cx = (k.cx + 0.5f) * 0.5f - 0.5f;
      k.cy = (k.cy + 0.5f) * 0.5f - 0.5f;
      k.width /= 2;
      k.height /= 2;
    }
    return k;
  }
};

}  // namespace seamless
