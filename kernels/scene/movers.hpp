// Things that move through the synthetic room (test material of dynamic scenes): a person walking, a ball
// rolling. Each is a handful of capsules (points within radius r of the segment a-b; a sphere is a
// capsule with a = b), posed per frame on the host (src/io/movers.cpp) and intersected here exactly
// by the renderer on either backend. World frame of synthetic_room.hpp: metres, z up.
#pragma once
#include <cstdint>

#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless::kernels::movers {

constexpr int kMaxCapsules = 32;

struct Capsule {
  vec3 a, b;
  float r;
  int mover;    // 1-based id of the mover it belongs to (the mask's value)
  vec3 albedo;  // linear RGB in [0, 1]
};

// The movers of one frame: a small POD passed to kernels by value.
struct Scene {
  int count = 0;
  Capsule c[kMaxCapsules];
};

struct Hit {
  float t;      // distance along the (unit) direction; < 0 when nothing was hit
  vec3 normal;  // outward normal
  int capsule;  // index into Scene::c
};

// Ray o + t d (|d| = 1) against a sphere of centre c, radius r: the entry t, or -1.
SEAMLESS_HD inline float ray_sphere(vec3 o, vec3 d, vec3 c, float r) {
  const vec3 oc = o - c;
  const float b = dot(oc, d), q = dot(oc, oc) - r * r;
  const float disc = b * b - q;
  if (disc < 0.f) return -1.f;
  const float t = -b - sqrtf(disc);
  return t > 0.f ? t : -1.f;
}

// Ray against a capsule, exactly: the infinite cylinder about a-b clipped to the segment's span,
// then the two end spheres (the nearest positive entry of the three is the capsule's surface).
SEAMLESS_HD inline float ray_capsule(vec3 o, vec3 d, const Capsule& cap, vec3* normal) {
  const vec3 ab = cap.b - cap.a;
  const float len2 = dot(ab, ab);
  float best = -1.f;
  if (len2 > 1e-12f) {
    // |(o + t d - a) x u|^2 = r^2 with u = ab / |ab|: a quadratic in t.
    const vec3 u = ab / sqrtf(len2), ao = o - cap.a;
    const vec3 dp = d - u * dot(d, u), op = ao - u * dot(ao, u);  // components across the axis
    const float A = dot(dp, dp), B = dot(op, dp), C = dot(op, op) - cap.r * cap.r;
    const float disc = B * B - A * C;
    if (A > 1e-12f && disc >= 0.f) {
      const float t = (-B - sqrtf(disc)) / A;
      const float s = dot(ao + d * t, u);  // position along the axis
      if (t > 0.f && s >= 0.f && s * s <= len2) {
        best = t;
        *normal = normalize(ao + d * t - u * s);
      }
    }
  }
  const vec3 ends[2] = {cap.a, cap.b};
  for (const vec3& e : ends) {
    const float t = ray_sphere(o, d, e, cap.r);
    if (t > 0.f && (best < 0.f || t < best)) {
      best = t;
      *normal = normalize(o + d * t - e);
    }
  }
  return best;
}

// First capsule hit along the ray, before tmax.
SEAMLESS_HD inline Hit raycast(const Scene& s, vec3 o, vec3 d, float tmax = 1e30f) {
  Hit h{-1.f, {0.f, 0.f, 0.f}, -1};
  for (int i = 0; i < s.count; ++i) {
    vec3 n{0.f, 0.f, 0.f};
    const float t = ray_capsule(o, d, s.c[i], &n);
    if (t > 0.f && t < tmax && (h.t < 0.f || t < h.t)) h = {t, n, i};
  }
  return h;
}

// Signed distance from p to the movers' surface (positive outside every capsule), and the capsule.
SEAMLESS_HD inline float distance(const Scene& s, vec3 p, int* nearest = nullptr) {
  float best = 1e30f;
  for (int i = 0; i < s.count; ++i) {
    const vec3 ab = s.c[i].b - s.c[i].a;
    const float len2 = dot(ab, ab);
    const float k = len2 > 1e-12f ? fminf(fmaxf(dot(p - s.c[i].a, ab) / len2, 0.f), 1.f) : 0.f;
    const float dist = length(p - (s.c[i].a + ab * k)) - s.c[i].r;
    if (dist < best) {
      best = dist;
      if (nearest) *nearest = i;
    }
  }
  return best;
}

}  // namespace seamless::kernels::movers
