// Unit quaternions (x, y, z, w) as rotations: rigid bodies' frames (core/particles.hpp), made and
// integrated by the solver, drawn by the renderer.
#pragma once
#include <cmath>

#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless {

SEAMLESS_HD inline vec4 quat_mul(vec4 a, vec4 b) {
  return {a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y, a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
          a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w, a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z};
}
SEAMLESS_HD inline vec4 quat_normalize(vec4 q) {
  float l = sqrtf(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w);
  return l > 0.f ? q * (1.f / l) : vec4{0.f, 0.f, 0.f, 1.f};
}
SEAMLESS_HD inline mat3 quat_to_mat(vec4 q) {
  float x = q.x, y = q.y, z = q.z, w = q.w;
  return {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
           {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
           {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

}  // namespace seamless
