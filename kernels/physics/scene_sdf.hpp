// The collision SDF of the static scene, as a small POD that kernels evaluate on either backend.
// Signed distance is positive in free space; the gradient points into free space.
//
// Sources, combined as a union (minimum distance):
//   - up to kMaxSdfPrimitives analytic primitives (half-space, solid box, container box, sphere);
//   - the built-in synthetic room (kernels/scene/synthetic_room.hpp), exact analytic SDF;
//   - a dense sampled grid (values filled on the host or by a TSDF sampler), trilinear with a
//     central-difference gradient. A TSDF from kernels/recon plugs in by filling this grid.
#pragma once
#include <cstdint>

#include "core/hd.hpp"
#include "core/math.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless::kernels {

enum SdfKind : int {
  kSdfHalfSpace = 0,  // solid below the plane dot(n, x) = offset; a = n (unit), b.x = offset
  kSdfBox = 1,        // solid box: centre a, half extents b, rotation R (local -> world)
  kSdfContainer = 2,  // hollow box (the solid is outside it): centre a, half extents b, rotation R
  kSdfSphere = 3,     // solid sphere: centre a, radius b.x
};

struct SdfPrimitive {
  int kind;
  vec3 a, b;
  mat3 R;
};

constexpr int kMaxSdfPrimitives = 8;

struct SdfSample3 {
  float d;
  vec3 grad;
};

struct SceneSdf {
  int count = 0;
  SdfPrimitive prims[kMaxSdfPrimitives];
  int synthetic_room = 0;       // 1: include kernels::room::room_sample
  const float* grid = nullptr;  // dense samples, x fastest; nullptr = none
  int3 dims{0, 0, 0};
  vec3 origin{0, 0, 0};  // world position of sample (0,0,0)
  float voxel = 0.f;     // sample spacing, metres
  SEAMLESS_HD bool active() const { return count > 0 || synthetic_room || grid != nullptr; }
};

SEAMLESS_HD inline float sg(float v) { return v < 0.f ? -1.f : 1.f; }

SEAMLESS_HD inline SdfSample3 sdf_local_box(vec3 l, vec3 h) {
  vec3 e{fabsf(l.x) - h.x, fabsf(l.y) - h.y, fabsf(l.z) - h.z};
  // max(e, 0) by comparisons: fmaxf is a libm call on x86-64 (its NaN rules), three per sample.
  vec3 out{e.x > 0.f ? e.x : 0.f, e.y > 0.f ? e.y : 0.f, e.z > 0.f ? e.z : 0.f};
  float lo = length(out);
  if (lo > 0.f) return {lo, vec3{sg(l.x) * out.x, sg(l.y) * out.y, sg(l.z) * out.z} / lo};
  if (e.x >= e.y && e.x >= e.z) return {e.x, {sg(l.x), 0.f, 0.f}};
  if (e.y >= e.z) return {e.y, {0.f, sg(l.y), 0.f}};
  return {e.z, {0.f, 0.f, sg(l.z)}};
}

SEAMLESS_HD inline SdfSample3 sdf_primitive(const SdfPrimitive& q, vec3 p) {
  switch (q.kind) {
    case kSdfHalfSpace: return {dot(q.a, p) - q.b.x, q.a};
    case kSdfSphere: {
      vec3 l = p - q.a;
      float r = length(l);
      return {r - q.b.x, r > 0.f ? l / r : vec3{0.f, 1.f, 0.f}};
    }
    default: {
      vec3 l = transpose(q.R) * (p - q.a);
      SdfSample3 s = sdf_local_box(l, q.b);
      if (q.kind == kSdfContainer) s = {-s.d, -s.grad};
      return {s.d, q.R * s.grad};
    }
  }
}

// Trilinear sample of the dense grid; outside the grid counts as far away (free space).
SEAMLESS_HD inline float sdf_grid_value(const SceneSdf& s, vec3 p) {
  vec3 g = (p - s.origin) / s.voxel;
  int3 c = floor_to_int(g);
  if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= s.dims.x - 1 || c.y >= s.dims.y - 1 || c.z >= s.dims.z - 1) return 1e30f;
  vec3 f = g - to_vec3(c);
  const std::int64_t sx = 1, sy = s.dims.x, sz = static_cast<std::int64_t>(s.dims.x) * s.dims.y;
  const float* q = s.grid + c.z * sz + c.y * sy + c.x;
  float c00 = q[0] * (1 - f.x) + q[sx] * f.x, c10 = q[sy] * (1 - f.x) + q[sy + sx] * f.x;
  float c01 = q[sz] * (1 - f.x) + q[sz + sx] * f.x, c11 = q[sz + sy] * (1 - f.x) + q[sz + sy + sx] * f.x;
  return (c00 * (1 - f.y) + c10 * f.y) * (1 - f.z) + (c01 * (1 - f.y) + c11 * f.y) * f.z;
}

SEAMLESS_HD inline SdfSample3 sdf_grid(const SceneSdf& s, vec3 p) {
  float d = sdf_grid_value(s, p);
  if (d > 1e29f) return {d, {0.f, 1.f, 0.f}};
  float e = 0.5f * s.voxel;
  vec3 g{sdf_grid_value(s, p + vec3{e, 0, 0}) - sdf_grid_value(s, p - vec3{e, 0, 0}),
         sdf_grid_value(s, p + vec3{0, e, 0}) - sdf_grid_value(s, p - vec3{0, e, 0}),
         sdf_grid_value(s, p + vec3{0, 0, e}) - sdf_grid_value(s, p - vec3{0, 0, e})};
  if (!(fabsf(g.x) < 1e29f && fabsf(g.y) < 1e29f && fabsf(g.z) < 1e29f)) return {d, {0.f, 1.f, 0.f}};
  return {d, normalize(g)};
}

// Union of every source: the nearest surface wins.
SEAMLESS_HD inline SdfSample3 scene_sdf(const SceneSdf& s, vec3 p) {
  SdfSample3 best{1e30f, {0.f, 1.f, 0.f}};
  for (int i = 0; i < s.count; ++i) {
    SdfSample3 q = sdf_primitive(s.prims[i], p);
    if (q.d < best.d) best = q;
  }
  if (s.synthetic_room) {
    room::RoomSample r = room::room_sample(p);
    if (r.d < best.d) best = {r.d, r.grad};
  }
  if (s.grid) {
    SdfSample3 q = sdf_grid(s, p);
    if (q.d < best.d) best = q;
  }
  return best;
}

}  // namespace seamless::kernels
