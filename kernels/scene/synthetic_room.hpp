// The built-in synthetic room: an indoor scene defined analytically, so that every layer can be
// tested against exact geometry. Usable on the host and in kernels (SEAMLESS_HD throughout).
//
// World frame: metres, z up, floor at z = 0 (like the TUM motion-capture frame), gravity -z.
// The room is 4 m (x) by 5 m (y) by 2.6 m (z), centred on x = y = 0. Inside it: a desk, a chair,
// a box, a sphere and a cylinder on the desk, a cabinet against a wall and a box on the floor.
//
// Every primitive has an exact signed distance function and an exact ray intersection; the scene
// is their union, so
//   room_sdf(p)       signed distance, positive in free space (exact wherever p is outside every
//                     solid: the distance to a union is the minimum of the distances);
//   room_sdf_grad(p)  its gradient (unit length in free space; the nearest primitive's gradient);
//   room_albedo(p)    the surface colour (linear RGB in [0, 1]) of the primitive nearest to p;
//   room_raycast(...) the first hit of a ray (distance, normal, primitive), for rendering.
#pragma once
#include <cstdint>

#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless::kernels::room {

enum Kind : int { kShell = 0, kBox = 1, kSphere = 2, kCylinder = 3 };
enum Pattern : int { kPlain = 0, kFloorTiles = 1, kWood = 2, kWalls = 3, kStripes = 4 };

// One solid. Box: half extents h, turned by yaw (radians) about the vertical through c.
// Sphere: radius h.x. Cylinder: vertical axis through c, radius h.x, half height h.z.
// Shell: the room's interior box (centre c, half extents h); the solid is everything outside it.
struct Primitive {
  int kind;
  vec3 c, h;
  float yaw;
  vec3 albedo;
  int pattern;
};

constexpr int kNumPrimitives = 17;
constexpr float kFloorZ = 0.f;
constexpr float kDeskTopZ = 0.75f;  // upper face of the desk top
SEAMLESS_HD inline vec3 room_centre() { return {0.f, 0.f, 1.3f}; }
SEAMLESS_HD inline vec3 room_half_extents() { return {2.f, 2.5f, 1.3f}; }
SEAMLESS_HD inline vec3 desk_centre() { return {0.f, 0.6f, kDeskTopZ}; }  // the cameras look here
SEAMLESS_HD inline vec3 gravity() { return {0.f, 0.f, -9.80665f}; }

// A switch rather than a table: a namespace-scope array would need __constant__ memory on CUDA.
SEAMLESS_HD inline Primitive primitive(int i) {
  const vec3 wood{0.55f, 0.36f, 0.2f}, metal{0.35f, 0.35f, 0.38f}, fabric{0.2f, 0.3f, 0.55f};
  switch (i) {
    case 0: return {kShell, room_centre(), room_half_extents(), 0.f, {0.8f, 0.78f, 0.72f}, kWalls};
    // desk: top and four legs
    case 1: return {kBox, {0.f, 0.6f, 0.73f}, {0.7f, 0.35f, 0.02f}, 0.f, wood, kWood};
    case 2: return {kBox, {-0.65f, 0.3f, 0.355f}, {0.025f, 0.025f, 0.355f}, 0.f, metal, kPlain};
    case 3: return {kBox, {0.65f, 0.3f, 0.355f}, {0.025f, 0.025f, 0.355f}, 0.f, metal, kPlain};
    case 4: return {kBox, {-0.65f, 0.9f, 0.355f}, {0.025f, 0.025f, 0.355f}, 0.f, metal, kPlain};
    case 5: return {kBox, {0.65f, 0.9f, 0.355f}, {0.025f, 0.025f, 0.355f}, 0.f, metal, kPlain};
    // chair: seat, back, four legs
    case 6: return {kBox, {0.15f, -0.05f, 0.45f}, {0.21f, 0.21f, 0.02f}, 0.f, fabric, kStripes};
    case 7: return {kBox, {0.15f, -0.25f, 0.72f}, {0.21f, 0.02f, 0.25f}, 0.f, fabric, kStripes};
    case 8: return {kBox, {-0.04f, -0.24f, 0.215f}, {0.02f, 0.02f, 0.215f}, 0.f, metal, kPlain};
    case 9: return {kBox, {0.34f, -0.24f, 0.215f}, {0.02f, 0.02f, 0.215f}, 0.f, metal, kPlain};
    case 10: return {kBox, {-0.04f, 0.14f, 0.215f}, {0.02f, 0.02f, 0.215f}, 0.f, metal, kPlain};
    case 11: return {kBox, {0.34f, 0.14f, 0.215f}, {0.02f, 0.02f, 0.215f}, 0.f, metal, kPlain};
    // on the desk: a turned box, a ball, a can
    case 12: return {kBox, {-0.3f, 0.65f, 0.8f}, {0.12f, 0.08f, 0.05f}, 0.5f, {0.85f, 0.25f, 0.2f}, kPlain};
    case 13: return {kSphere, {0.15f, 0.55f, 0.85f}, {0.1f, 0.1f, 0.1f}, 0.f, {0.2f, 0.7f, 0.3f}, kPlain};
    case 14: return {kCylinder, {0.4f, 0.72f, 0.85f}, {0.05f, 0.05f, 0.1f}, 0.f, {0.9f, 0.8f, 0.2f}, kStripes};
    // a cabinet against the -x wall and a box on the floor
    case 15: return {kBox, {-1.75f, 1.5f, 0.5f}, {0.25f, 0.5f, 0.5f}, 0.f, {0.7f, 0.7f, 0.75f}, kPlain};
    default: return {kBox, {1.2f, 1.2f, 0.2f}, {0.2f, 0.2f, 0.2f}, 0.3f, {0.6f, 0.45f, 0.3f}, kWood};
  }
}

// ---- small helpers ---------------------------------------------------------------------------

SEAMLESS_HD inline float sgn(float v) { return v < 0.f ? -1.f : 1.f; }
// Rotation about z by +a (local -> world) and -a (world -> local).
SEAMLESS_HD inline vec3 rot_z(vec3 p, float a) {
  float c = cosf(a), s = sinf(a);
  return {c * p.x - s * p.y, s * p.x + c * p.y, p.z};
}
SEAMLESS_HD inline vec3 to_local(const Primitive& q, vec3 p) { return rot_z(p - q.c, -q.yaw); }
SEAMLESS_HD inline float comp(vec3 v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }
SEAMLESS_HD inline vec3 axis(int i, float s) { return {i == 0 ? s : 0.f, i == 1 ? s : 0.f, i == 2 ? s : 0.f}; }

// Distance and gradient of one primitive at p.
struct SdfSample {
  float d;
  vec3 grad;
};

// Inside an axis-aligned box the exact distance to its boundary is the smallest slab distance.
SEAMLESS_HD inline SdfSample sdf_shell(const Primitive& q, vec3 p) {
  vec3 l = p - q.c;
  SdfSample best{1e30f, {0.f, 0.f, 0.f}};
  for (int i = 0; i < 3; ++i) {
    float d = comp(q.h, i) - fabsf(comp(l, i));
    if (d < best.d) best = {d, axis(i, -sgn(comp(l, i)))};
  }
  return best;
}

// Exact box SDF (the usual "length(max(q,0)) + min(maxcomp(q),0)" with q = |p| - h).
SEAMLESS_HD inline SdfSample sdf_box(const Primitive& q, vec3 p) {
  vec3 l = to_local(q, p);
  vec3 e{fabsf(l.x) - q.h.x, fabsf(l.y) - q.h.y, fabsf(l.z) - q.h.z};
  vec3 out = vmax(e, vec3{0.f, 0.f, 0.f});
  float lo = length(out);
  vec3 g;
  float d;
  if (lo > 0.f) {
    d = lo;
    g = vec3{sgn(l.x) * out.x, sgn(l.y) * out.y, sgn(l.z) * out.z} / lo;
  } else {  // inside: the nearest face is the one with the largest (least negative) e
    int i = (e.x >= e.y && e.x >= e.z) ? 0 : (e.y >= e.z ? 1 : 2);
    d = comp(e, i);
    g = axis(i, sgn(comp(l, i)));
  }
  return {d, rot_z(g, q.yaw)};
}

SEAMLESS_HD inline SdfSample sdf_sphere(const Primitive& q, vec3 p) {
  vec3 l = p - q.c;
  float r = length(l);
  return {r - q.h.x, r > 0.f ? l / r : vec3{0.f, 0.f, 1.f}};
}

// Capped vertical cylinder: 2-D box SDF in (radial distance, height).
SEAMLESS_HD inline SdfSample sdf_cylinder(const Primitive& q, vec3 p) {
  vec3 l = p - q.c;
  float r = sqrtf(l.x * l.x + l.y * l.y);
  vec3 radial = r > 0.f ? vec3{l.x / r, l.y / r, 0.f} : vec3{1.f, 0.f, 0.f};
  float a = r - q.h.x, b = fabsf(l.z) - q.h.z;
  vec3 up{0.f, 0.f, sgn(l.z)};
  if (a > 0.f && b > 0.f) {
    float d = sqrtf(a * a + b * b);
    return {d, (radial * a + up * b) / d};
  }
  // Outside past one face only, or inside (nearest of side and cap): the larger of the two.
  return a > b ? SdfSample{a, radial} : SdfSample{b, up};
}

SEAMLESS_HD inline SdfSample primitive_sdf(const Primitive& q, vec3 p) {
  switch (q.kind) {
    case kShell: return sdf_shell(q, p);
    case kBox: return sdf_box(q, p);
    case kSphere: return sdf_sphere(q, p);
    default: return sdf_cylinder(q, p);
  }
}

// ---- the scene's SDF -------------------------------------------------------------------------

struct RoomSample {
  float d;    // signed distance, metres (positive in free space)
  vec3 grad;  // gradient of d
  int id;     // nearest primitive
};

SEAMLESS_HD inline RoomSample room_sample(vec3 p) {
  RoomSample best{1e30f, {0.f, 0.f, 1.f}, 0};
  for (int i = 0; i < kNumPrimitives; ++i) {
    SdfSample s = primitive_sdf(primitive(i), p);
    if (s.d < best.d) best = {s.d, s.grad, i};
  }
  return best;
}
SEAMLESS_HD inline float room_sdf(vec3 p) { return room_sample(p).d; }
SEAMLESS_HD inline vec3 room_sdf_grad(vec3 p) { return room_sample(p).grad; }

// ---- colour ----------------------------------------------------------------------------------

// Procedural texture so that photometric trackers have something to lock on to. Deterministic.
SEAMLESS_HD inline vec3 pattern_colour(const Primitive& q, vec3 p) {
  vec3 a = q.albedo;
  switch (q.pattern) {
    case kFloorTiles: {  // only the floor face of the shell gets here
      int cx = static_cast<int>(floorf(p.x / 0.5f)), cy = static_cast<int>(floorf(p.y / 0.5f));
      float k = ((cx + cy) & 1) ? 0.55f : 0.85f;
      return vec3{0.75f, 0.7f, 0.6f} * k;
    }
    case kWalls: {  // horizontal dado band plus a grid of coloured "posters"
      float u = p.x + p.y, v = p.z;
      float band = (v > 0.9f && v < 1.0f) ? 0.6f : 1.f;
      vec3 c = a * band;
      if (v > 1.2f && v < 2.0f) {
        int cell = static_cast<int>(floorf(u / 0.4f)) & 3;
        vec3 poster[4] = {{0.8f, 0.2f, 0.2f}, {0.2f, 0.5f, 0.8f}, {0.9f, 0.8f, 0.3f}, {0.3f, 0.7f, 0.4f}};
        float stripes = 0.75f + 0.25f * sinf(v * 40.f);
        if (fmodf(fabsf(u), 0.8f) < 0.6f) c = poster[cell] * stripes;
      }
      return c;
    }
    case kWood: return a * (0.8f + 0.2f * sinf(60.f * (p.x + 0.3f * p.y) + 3.f * sinf(7.f * p.y)));
    case kStripes: return a * (0.7f + 0.3f * sinf(50.f * p.z));
    default: return a;
  }
}

// The floor and the ceiling of the shell are not walls.
SEAMLESS_HD inline vec3 surface_colour(int id, vec3 p) {
  Primitive q = primitive(id);
  if (q.kind == kShell) {
    if (p.z < 0.01f) q.pattern = kFloorTiles;
    else if (p.z > 2 * q.h.z - 0.01f) q.pattern = kPlain;
  }
  return pattern_colour(q, p);
}

SEAMLESS_HD inline vec3 room_albedo(vec3 p) { return surface_colour(room_sample(p).id, p); }

// ---- ray casting -----------------------------------------------------------------------------

struct Hit {
  float t;      // distance along the (unit) direction; < 0 when nothing was hit
  vec3 normal;  // outward surface normal (pointing into free space)
  int id;
};

// Ray against an axis-aligned box in local coordinates (slab method); entry only, o outside.
SEAMLESS_HD inline Hit hit_local_box(vec3 o, vec3 d, vec3 h) {
  float tn = -1e30f, tf = 1e30f;
  int ax = 0;
  for (int i = 0; i < 3; ++i) {
    float oi = comp(o, i), di = comp(d, i), hi = comp(h, i);
    if (fabsf(di) < 1e-12f) {
      if (fabsf(oi) > hi) return {-1.f, {0, 0, 0}, 0};
      continue;
    }
    float t1 = (-hi - oi) / di, t2 = (hi - oi) / di;
    if (t1 > t2) {
      float s = t1;
      t1 = t2;
      t2 = s;
    }
    if (t1 > tn) {
      tn = t1;
      ax = i;
    }
    if (t2 < tf) tf = t2;
  }
  if (tn > tf || tn <= 0.f) return {-1.f, {0, 0, 0}, 0};
  return {tn, axis(ax, -sgn(comp(d, ax))), 0};
}

SEAMLESS_HD inline Hit hit_shell(const Primitive& q, vec3 o, vec3 d) {
  vec3 l = o - q.c;
  Hit best{1e30f, {0, 0, 0}, 0};
  for (int i = 0; i < 3; ++i) {
    float di = comp(d, i);
    if (fabsf(di) < 1e-12f) continue;
    float t = (sgn(di) * comp(q.h, i) - comp(l, i)) / di;
    if (t < best.t) best = {t, axis(i, -sgn(di)), 0};
  }
  return best;
}

SEAMLESS_HD inline Hit hit_box(const Primitive& q, vec3 o, vec3 d) {
  Hit h = hit_local_box(to_local(q, o), rot_z(d, -q.yaw), q.h);
  h.normal = rot_z(h.normal, q.yaw);
  return h;
}

SEAMLESS_HD inline Hit hit_sphere(const Primitive& q, vec3 o, vec3 d) {
  vec3 l = o - q.c;
  float b = dot(l, d), c = dot(l, l) - q.h.x * q.h.x;
  float disc = b * b - c;
  if (disc < 0.f) return {-1.f, {0, 0, 0}, 0};
  // Numerically stable root: c / (-b + sqrt) when b < 0 avoids cancellation.
  float s = sqrtf(disc);
  float t = b < 0.f ? c / (-b + s) : -b - s;
  if (t <= 0.f) return {-1.f, {0, 0, 0}, 0};
  return {t, normalize(l + d * t), 0};
}

SEAMLESS_HD inline Hit hit_cylinder(const Primitive& q, vec3 o, vec3 d) {
  vec3 l = o - q.c;
  Hit best{-1.f, {0, 0, 0}, 0};
  // side: |(l + t d)_xy| = R
  float a = d.x * d.x + d.y * d.y;
  if (a > 1e-12f) {
    float b = l.x * d.x + l.y * d.y, c = l.x * l.x + l.y * l.y - q.h.x * q.h.x;
    float disc = b * b - a * c;
    if (disc >= 0.f) {
      float s = sqrtf(disc);
      float t = b < 0.f ? c / (-b + s) : (-b - s) / a;
      float z = l.z + t * d.z;
      if (t > 0.f && fabsf(z) <= q.h.z) best = {t, normalize(vec3{l.x + t * d.x, l.y + t * d.y, 0.f}), 0};
    }
  }
  // caps: z = +-H
  if (fabsf(d.z) > 1e-12f) {
    float zc = l.z > 0.f ? q.h.z : -q.h.z;
    float t = (zc - l.z) / d.z;
    float x = l.x + t * d.x, y = l.y + t * d.y;
    if (t > 0.f && x * x + y * y <= q.h.x * q.h.x && (best.t < 0.f || t < best.t)) best = {t, {0.f, 0.f, sgn(zc)}, 0};
  }
  return best;
}

SEAMLESS_HD inline Hit primitive_hit(const Primitive& q, vec3 o, vec3 d) {
  switch (q.kind) {
    case kShell: return hit_shell(q, o, d);
    case kBox: return hit_box(q, o, d);
    case kSphere: return hit_sphere(q, o, d);
    default: return hit_cylinder(q, o, d);
  }
}

// First surface along o + t d (d unit length) for t in (0, tmax]; t < 0 when none.
// The camera must be in free space (inside the room, outside every object).
SEAMLESS_HD inline Hit room_raycast(vec3 o, vec3 d, float tmax = 1e30f) {
  Hit best{tmax, {0, 0, 0}, -1};
  for (int i = 0; i < kNumPrimitives; ++i) {
    Hit h = primitive_hit(primitive(i), o, d);
    if (h.t > 0.f && h.t < best.t) best = {h.t, h.normal, i};
  }
  if (best.id < 0) best.t = -1.f;
  return best;
}

}  // namespace seamless::kernels::room
