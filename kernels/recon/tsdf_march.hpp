// One ray's march through the TSDF (the raycast's per-pixel work, tsdf_raycast.inl), compiled
// once per backend. The CPU also marches 8 rays at once on SIMD lanes with the same operations in
// the same order (tsdf_march_simd.hpp), so both take the same samples and find the same hits.
#pragma once
#include <cmath>

#include "kernels/recon/tsdf.hpp"

namespace seamless::kernels {

// Ray parameter at which the ray o + t d (voxel units) leaves block b (slab method); inv_d is
// 1 / d per axis (computed once per ray: a division is a subroutine on the GPU).
SEAMLESS_HD inline float block_exit(vec3 o, vec3 d, vec3 inv_d, int3 b) {
  float t = 1e30f;
  float lo[3] = {b.x * 8.f, b.y * 8.f, b.z * 8.f};
  float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z}, ii[3] = {inv_d.x, inv_d.y, inv_d.z};
  for (int k = 0; k < 3; ++k) {
    if (dd[k] > 0.f) t = min_of(t, (lo[k] + 8.f - oo[k]) * ii[k]);
    if (dd[k] < 0.f) t = min_of(t, (lo[k] - oo[k]) * ii[k]);
  }
  return t;
}

// Whether block i (>= 0) may hold a surface for the march: false only where the accessor has
// near-surface flags (a volume storing free space; block_near_surface in tsdf.hpp) and block i's
// is 0, so that the march skips it like an unallocated block.
template <class Acc> SEAMLESS_HD inline bool near_surface(const Acc& a, std::int32_t i) {
  if constexpr (requires { a.near_surface; }) {
    return !a.near_surface || a.near_surface[i];
  } else {
    return true;
  }
}

// A pixel's ray in voxel units, parametrised by camera depth z: point(z) = o + d z, marched from z
// to z_end.
struct PixelRay {
  vec3 o, d;
  float z = 0.f, z_end = 0.f;
};

// The ray through pixel (x, y)'s centre, over its tile's interval when iv.bits is set (Niessner
// section 4.3: march only where blocks are; no block in the tile: an empty interval).
SEAMLESS_HD inline PixelRay pixel_ray(const VoxelGeometry& g, int x, int y, const Intrinsics& K,
                                      const SE3& world_T_camera, float min_depth, float max_depth,
                                      const RayIntervals& iv) {
  PixelRay r;
  const vec3 dir_c = K.unproject(static_cast<float>(x), static_cast<float>(y), 1.f);
  r.o = g.to_voxel(world_T_camera.t);
  r.d = world_T_camera.rotate(dir_c) / g.voxel_size;
  const float min_step = 0.5f / length(r.d);  // half a voxel
  r.z = min_depth, r.z_end = max_depth;
  if (iv.bits) {
    const std::int64_t t = iv.tile_of(x, y);
    const float z_near = bits_float(iv.bits[2 * t]), z_far = bits_float(iv.bits[2 * t + 1]);
    r.z = max_of(z_near - min_step, r.z), r.z_end = z_far > 0.f ? min_of(z_far + min_step, r.z_end) : 0.f;
  }
  return r;
}

// The march's step lengths along a ray of direction d (voxel units per metre of depth), in units
// of z.
struct MarchSteps {
  float min_step;         // half a voxel
  float unobserved_step;  // through cells without a value
  float step_per_sdf;     // z per metre of TSDF value
  vec3 inv_d;             // 1 / d per axis, +-inf on an axis d does not move along
};
SEAMLESS_HD inline MarchSteps march_steps(const VoxelGeometry& g, vec3 d) {
  const float dlen = length(d);  // voxels per metre of depth
  MarchSteps s;
  s.min_step = 0.5f / dlen;
  // Where a cell is unobserved no crossing can be found, and observed space reaches at least the
  // truncation distance mu in front of every fused surface (fusion writes every voxel of the
  // band from +mu on, see fuse_voxel). Steps of mu/2 through unobserved cells therefore land at
  // least one observed sample in front of the next surface, where the march takes over.
  s.unobserved_step = max_of(s.min_step, 0.5f * g.truncation / (dlen * g.voxel_size));
  // |TSDF| is at most about the distance to the nearest zero crossing (projective distances
  // over-estimate at grazing angles, hence the 0.8), so stepping that far along the ray (|d| s
  // metres per unit of z) cannot jump over one: truncation-sized steps in the band's free-space
  // side (and through the back of a surface a ray enters from behind), shrinking to half a
  // voxel at the surface.
  s.step_per_sdf = 0.8f / (dlen * g.voxel_size);
  s.inv_d = {1.f / d.x, 1.f / d.y, 1.f / d.z};
  return s;
}

// Steps of regula falsi that refine a bracketed crossing, and the most steps a ray takes.
constexpr int kRefineSteps = 3, kMaxMarchSteps = 8192;

// Marches the ray r from r.z to r.z_end; on a +/- zero crossing returns true with its refined
// depth in *hit and the block cache left near it. The crossing is refined by kRefineSteps steps of
// regula falsi on the trilinear field, taken by the same loop: its samples then run through the
// one copy of the sample code (on the GPU the kernel's size, not its arithmetic, held the march
// back: most warps waited on instruction fetch).
template <class Acc> SEAMLESS_HD inline bool march_ray(const Acc& a, const PixelRay& r, BlockCache& c, float* hit) {
  const vec3 o = r.o, d = r.d;
  const MarchSteps s = march_steps(a.geom, d);
  float z = r.z;
  float z_prev = 0.f, f_prev = 0.f;
  bool have_prev = false, prev_near = false;     // prev_near: the last sample's block is near a surface
  int refine = -1;                               // -1: marching; else regula falsi steps taken
  float ta = 0.f, fa = 0.f, tb = 0.f, fb = 0.f;  // the bracket: fa > 0 at ta, fb <= 0 at tb
  for (int it = 0; refine >= 0 || (it < kMaxMarchSteps && z < r.z_end); ++it) {
    vec3 q = o + d * z;
    const int3 g0 = floor_to_int(q), b = block_of_voxel(g0);
    const std::int32_t i0 = cached_block(a, b, c);
    // Skipped: unallocated, or not near a surface while marching (not while refining a bracket),
    // except for one sample right after a sample in a block near a surface: a crossing between
    // the two (the step from the last sample in front of a surface may land past it) is then
    // bracketed as without the flags (block_near_surface in tsdf.hpp).
    const bool near = i0 >= 0 && (refine >= 0 || near_surface(a, i0));
    const bool skip = i0 < 0 || (!near && !(have_prev && prev_near));
    float f = 0.f;
    const bool sampled = !skip && sample_tsdf_in(a, q, g0, i0, c, &f);  // the block just found: no second lookup
    if (refine >= 0) {                                                  // regula falsi between the bracket's ends
      if (!sampled) break;  // no value here: the last estimate, z, is the hit
      if (f > 0.f) ta = z, fa = f;
      else tb = z, fb = f;
      z = ta + (tb - ta) * fa / (fa - fb);
      if (++refine == kRefineSteps) break;
      continue;
    }
    if (skip) {  // empty space: skip the whole block (Niessner section 4.3)
      z = max_of(block_exit(o, d, s.inv_d, b), z) + s.min_step * 0.1f;
      have_prev = false;
      continue;
    }
    if (!sampled) {
      z += s.unobserved_step;
      have_prev = false;
      continue;
    }
    if (have_prev && f_prev > 0.f && f <= 0.f) {
      ta = z_prev, fa = f_prev, tb = z, fb = f, refine = 0;
      z = ta + (tb - ta) * fa / (fa - fb);
      continue;
    }
    z_prev = z, f_prev = f, have_prev = true, prev_near = near;
    z += max_of(fabsf(f) * s.step_per_sdf, s.min_step);
  }
  if (refine < 0) return false;
  *hit = z;
  return true;
}

// Writes pixel (x, y)'s outputs for its ray r: the hit at depth zh when hit, zero otherwise.
template <class Acc>
SEAMLESS_HD inline void write_pixel(const Acc& a, int x, int y, const PixelRay& r, bool hit, float zh, BlockCache& c,
                                    const RaycastOutput& out) {
  float fh = 0.f;
  vec3 col{0.f, 0.f, 0.f}, vw{0.f, 0.f, 0.f};
  if (!hit) zh = 0.f;
  if (hit) {
    const vec3 qh = r.o + r.d * zh;
    if (out.color.data) sample_tsdf(a, qh, c, &fh, &col);  // no colour wanted: no ninth sample
    vw = a.geom.to_world(qh);
  }
  out.depth(x, y) = zh;  // each output written once; zero where no hit
  out.vertex(x, y) = vw;
  if (out.color.data)
    out.color(x, y) = {static_cast<std::uint8_t>(col.x + 0.5f), static_cast<std::uint8_t>(col.y + 0.5f),
                       static_cast<std::uint8_t>(col.z + 0.5f)};
}

// Normal of pixel (x, y) from its neighbours' vertices (as InfiniTAM does after its raycast): the
// cross product of central differences along the image axes (one-sided at a missing neighbour),
// facing the camera at eye. A neighbour farther than max_jump is across a depth discontinuity and
// not used; zero where either axis has no usable neighbour. On the raycast's smooth TSDF surface
// this costs one pass over the image, where the TSDF gradient (six more trilinear samples per
// hit, often in other blocks) took half of the raycast's GPU time.
SEAMLESS_HD inline vec3 vertex_map_normal(View2D<const vec3> vtx, View2D<const float> depth, int x, int y, vec3 eye,
                                          float max_jump) {
  const vec3 v = vtx(x, y);
  auto neighbour = [&](int xx, int yy, vec3* out) {
    if (!vtx.inside(xx, yy) || !(depth(xx, yy) > 0.f)) return false;
    *out = vtx(xx, yy);
    return length2(*out - v) <= max_jump * max_jump;
  };
  auto axis_diff = [&](int dx, int dy, vec3* d) {
    vec3 p{}, m{};  // set by neighbour() when it returns true; zeroed for the compiler's flow analysis
    const bool hp = neighbour(x + dx, y + dy, &p), hm = neighbour(x - dx, y - dy, &m);
    if (hp && hm) *d = p - m;
    else if (hp) *d = p - v;
    else if (hm) *d = v - m;
    return hp || hm;
  };
  vec3 du, dv;
  if (!axis_diff(1, 0, &du) || !axis_diff(0, 1, &dv)) return {0.f, 0.f, 0.f};
  vec3 n = normalize(cross(dv, du));
  return dot(n, eye - v) < 0.f ? n * -1.f : n;
}

// The raycast's normal map at pixel (x, y): vertex_map_normal with the silhouette threshold at the
// pixel's depth (zero where the ray hit nothing).
SEAMLESS_HD inline vec3 pixel_normal(View2D<const vec3> vtx, View2D<const float> depth, int x, int y, vec3 eye,
                                     float jump_per_metre) {
  const float z = depth(x, y);
  return z > 0.f ? vertex_map_normal(vtx, depth, x, y, eye, jump_per_metre * z) : vec3{0.f, 0.f, 0.f};
}

template <class Acc>
SEAMLESS_HD inline void raycast_pixel(const Acc& a, int x, int y, const Intrinsics& K, const SE3& world_T_camera,
                                      float min_depth, float max_depth, const RaycastOutput& out,
                                      const RayIntervals& iv) {
  const PixelRay r = pixel_ray(a.geom, x, y, K, world_T_camera, min_depth, max_depth, iv);
  BlockCache c;
  float zh = 0.f;
  const bool hit = march_ray(a, r, c, &zh);
  write_pixel(a, x, y, r, hit, zh, c, out);
}

}  // namespace seamless::kernels
