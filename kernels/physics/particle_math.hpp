// Per-element math of the particle solver (host and device): phase flags, SPH kernels, the
// neighbour grid's cell keys, quaternions and the rotation extraction of shape matching.
#pragma once
#include <cstdint>

#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless::kernels {

// Phase word of a dynamic particle (Macklin 2014, section 4.3): a group id in the low 24 bits
// (rigid body id, cloth id) and flags above. Static scene particles live in their own arrays.
namespace phase {
constexpr std::uint32_t kGroupMask = 0x00FFFFFFu;
constexpr std::uint32_t kFluid = 1u << 24;
constexpr std::uint32_t kRigid = 1u << 25;
constexpr std::uint32_t kCloth = 1u << 26;
constexpr std::uint32_t kSelfCollide = 1u << 27;
constexpr std::uint32_t kStatic = 1u << 28;
SEAMLESS_HD inline std::uint32_t group(std::uint32_t ph) { return ph & kGroupMask; }
SEAMLESS_HD inline bool is(std::uint32_t ph, std::uint32_t flag) { return (ph & flag) != 0u; }
}  // namespace phase

constexpr float kPi = 3.14159265358979f;

// Poly6 kernel (Mueller 2003, used for density in Macklin & Mueller 2013, eq. 2).
SEAMLESS_HD inline float poly6(float r2, float h) {
  if (r2 >= h * h) return 0.f;
  float h2 = h * h, t = h2 - r2;
  return 315.f / (64.f * kPi * h2 * h2 * h2 * h2 * h) * t * t * t;
}

// Gradient of the spiky kernel with respect to p_i for r = p_i - p_j (Mueller 2003; PBF eq. 8).
SEAMLESS_HD inline vec3 spiky_grad(vec3 r, float h) {
  float l = length(r);
  if (l >= h || l <= 1e-12f) return {0.f, 0.f, 0.f};
  float t = h - l;
  return r * (-45.f / (kPi * h * h * h * h * h * h) * t * t / l);
}

// Akinci 2013 cohesion spline C(r) (eq. 2 there), zero beyond h.
SEAMLESS_HD inline float akinci_spline(float r, float h) {
  if (r >= h || r <= 0.f) return 0.f;
  float k = 32.f / (kPi * h * h * h * h * h * h * h * h * h);
  float a = (h - r) * (h - r) * (h - r) * r * r * r;
  if (2.f * r > h) return k * a;
  float h6 = h * h * h * h * h * h;
  return k * (2.f * a - h6 / 64.f);
}

// ---- neighbour grid -------------------------------------------------------------------------
// A periodic uniform grid of 2^bits cells per axis: cell coordinates wrap, so the grid covers all
// of space, and with at least 3 cells per axis the 27 cells around a particle are 27 distinct
// buckets (no particle is visited twice). Far-apart particles may share a bucket; the distance
// test removes them.
struct GridSpec {
  float inv_cell;  // 1 / cell size
  int bits;        // cells per axis = 1 << bits
  SEAMLESS_HD std::uint32_t key(int3 c) const {
    std::uint32_t m = (1u << bits) - 1u;
    return (static_cast<std::uint32_t>(c.x) & m) | ((static_cast<std::uint32_t>(c.y) & m) << bits) |
           ((static_cast<std::uint32_t>(c.z) & m) << (2 * bits));
  }
  SEAMLESS_HD int3 cell(vec3 p) const { return floor_to_int(p * inv_cell); }
  SEAMLESS_HD std::int64_t cells() const { return std::int64_t{1} << (3 * bits); }
};

// ---- quaternions (x, y, z, w) ------------------------------------------------------------------
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

// Rotational part of A (Mueller, Bender, Chentanez, Macklin 2016, "A Robust Method to Extract the
// Rotational Part of Deformations", eq. 7): rotate q towards the column-wise alignment of R(q)
// with A until the angular step is negligible. Warm-started from the previous frame's q, it needs
// few iterations and never fails on flat or inverted A, unlike a closed-form polar decomposition.
SEAMLESS_HD inline vec4 extract_rotation(const mat3& A, vec4 q, int max_iter) {
  for (int it = 0; it < max_iter; ++it) {
    mat3 R = quat_to_mat(q);
    vec3 num = cross(R.col(0), A.col(0)) + cross(R.col(1), A.col(1)) + cross(R.col(2), A.col(2));
    float den = fabsf(dot(R.col(0), A.col(0)) + dot(R.col(1), A.col(1)) + dot(R.col(2), A.col(2))) + 1e-9f;
    vec3 omega = num / den;
    float w = length(omega);
    if (w < 1e-9f) break;
    vec3 axis = omega / w;
    float s = sinf(0.5f * w);
    q = quat_normalize(quat_mul(vec4{axis.x * s, axis.y * s, axis.z * s, cosf(0.5f * w)}, q));
  }
  return q;
}

}  // namespace seamless::kernels
