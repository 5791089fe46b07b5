// Kernel bodies for raycasting in recon/tsdf.hpp, compiled once per backend.
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

// Pixel bounding box and camera-depth range of a block's cell box clipped to the depth slab.
struct ScreenBounds {
  float u0 = 1e30f, u1 = -1e30f, v0 = 1e30f, v1 = -1e30f, z0 = 1e30f, z1 = -1e30f;
  SEAMLESS_HD void add(vec3 p, const Intrinsics& K) {
    vec2 uv = K.project(p);
    u0 = fminf(u0, uv.x), u1 = fmaxf(u1, uv.x), v0 = fminf(v0, uv.y), v1 = fmaxf(v1, uv.y);
    z0 = fminf(z0, p.z), z1 = fmaxf(z1, p.z);
  }
};

// Bounds of block b's cell box [8b, 8b+8]^3 (voxel units) seen from the camera, clipped to the
// slab zn <= z <= zf (zn > 0): the clipped box is convex, and its vertices are the box corners
// inside the slab and the crossings of the 12 box edges with the two planes. False when empty.
SEAMLESS_HD inline bool block_screen_bounds(int3 b, const VoxelGeometry& g, const Intrinsics& K,
                                            const SE3& camera_T_world, float zn, float zf, ScreenBounds* out) {
  vec3 pc[8];
  for (int k = 0; k < 8; ++k) {
    int3 v{8 * (b.x + (k & 1)), 8 * (b.y + ((k >> 1) & 1)), 8 * (b.z + (k >> 2))};
    pc[k] = camera_T_world * g.to_world(to_vec3(v));
  }
  ScreenBounds s;
  for (int k = 0; k < 8; ++k) {
    if (pc[k].z >= zn && pc[k].z <= zf) s.add(pc[k], K);
    for (int axis = 0; axis < 3; ++axis) {  // edge k -> j along axis, each edge once
      if (k & (1 << axis)) continue;
      vec3 p = pc[k], q = pc[k | (1 << axis)];
      const float planes[2] = {zn, zf};
      for (float plane : planes) {
        if ((p.z - plane) * (q.z - plane) >= 0.f) continue;
        vec3 c = p + (q - p) * ((plane - p.z) / (q.z - p.z));
        c.z = plane;
        s.add(c, K);
      }
    }
  }
  *out = s;
  return s.z0 <= s.z1;
}

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::clear_ray_intervals(const Exec& ex, RayIntervals iv, BlockWindow w) {
  const std::int64_t tiles = iv.count(), entries = w.index ? w.count() : 0;
  ex.for_each(tiles > entries ? tiles : entries, [=] SEAMLESS_HD(std::int64_t t) {
    if (t < entries) w.index[t] = -1;
    if (t >= tiles) return;
    iv.bits[2 * t] = kEmptyNear;
    iv.bits[2 * t + 1] = kEmptyFar;
  });
}

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::splat_ray_intervals(const Exec& ex, HashTableView t, VoxelGeometry geom, Intrinsics K,
                                                 SE3 world_T_camera, float min_depth, float max_depth, RayIntervals iv,
                                                 BlockWindow w, const std::int32_t* surface, std::int32_t* near) {
  const SE3 camera_T_world = world_T_camera.inverse();
  const float zn = fmaxf(min_depth, 1e-3f);
  ex.for_each(static_cast<std::int64_t>(t.mask) + 1, [=] SEAMLESS_HD(std::int64_t i) {
    HashKey k = t.keys[i];
    const std::int32_t block = t.values[i];
    if (!is_live_key(k) || block < 0) return;
    if (w.index) {
      const std::int64_t e = w.entry(unpack_block(k));
      if (e >= 0) w.index[e] = block;  // keys are unique: one writer per entry
    }
    if (surface) {  // a block the march skips needs no interval (see block_near_surface)
      const bool n = block_near_surface(t, surface, unpack_block(k), block);
      near[block] = n ? 1 : 0;
      if (!n) return;
    }
    ScreenBounds s;
    if (!block_screen_bounds(unpack_block(k), geom, K, camera_T_world, zn, max_depth, &s)) return;
    // Rays go through pixel centres: pixel x can meet the box only if u0 <= x <= u1. Rounding
    // outwards keeps the splat conservative.
    if (s.u1 < 0.f || s.v1 < 0.f || s.u0 > K.width - 1.f || s.v0 > K.height - 1.f) return;
    const int x0 = static_cast<int>(floorf(fmaxf(s.u0, 0.f))), x1 = static_cast<int>(ceilf(fminf(s.u1, K.width - 1.f)));
    const int y0 = static_cast<int>(floorf(fmaxf(s.v0, 0.f))),
              y1 = static_cast<int>(ceilf(fminf(s.v1, K.height - 1.f)));
    const std::int32_t z_near = float_bits(s.z0), z_far = float_bits(s.z1);
    for (int ty = y0 / iv.tile; ty <= y1 / iv.tile; ++ty)
      for (int tx = x0 / iv.tile; tx <= x1 / iv.tile; ++tx) {
        std::int32_t* tile = iv.bits + 2 * iv.tile_of(tx * iv.tile, ty * iv.tile);
        atomic_min(tile, z_near);
        atomic_max(tile + 1, z_far);
      }
  });
}

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::mark_near_surface(const Exec& ex, HashTableView t, const std::int32_t* surface,
                                               std::int32_t* near) {
  ex.for_each(static_cast<std::int64_t>(t.mask) + 1, [=] SEAMLESS_HD(std::int64_t i) {
    const HashKey k = t.keys[i];
    const std::int32_t block = t.values[i];
    if (!is_live_key(k) || block < 0) return;
    near[block] = block_near_surface(t, surface, unpack_block(k), block) ? 1 : 0;
  });
}

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::fill_block_window(const Exec& ex, HashTableView t, BlockWindow w) {
  ex.for_each(w.count(), [=] SEAMLESS_HD(std::int64_t i) { w.index[i] = -1; });
  ex.for_each(static_cast<std::int64_t>(t.mask) + 1, [=] SEAMLESS_HD(std::int64_t i) {
    const HashKey k = t.keys[i];
    if (!is_live_key(k) || t.values[i] < 0) return;
    const std::int64_t e = w.entry(unpack_block(k));
    if (e >= 0) w.index[e] = t.values[i];  // keys are unique: one writer per entry
  });
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

// Marches the ray o + d z (voxel units, z = camera depth) from z to z_end; on a +/- zero crossing
// returns true with its refined depth in *hit and the block cache left near it. The crossing is
// refined by three steps of regula falsi on the trilinear field, taken by the same loop: its
// samples then run through the one copy of the sample code (on the GPU the kernel's size, not its
// arithmetic, held the march back: most warps waited on instruction fetch).
template <class Acc>
SEAMLESS_HD inline bool march_ray(const Acc& a, vec3 o, vec3 d, float z, float z_end, BlockCache& c, float* hit) {
  const float dlen = length(d);        // voxels per metre of depth
  const float min_step = 0.5f / dlen;  // half a voxel
  // Where a cell is unobserved no crossing can be found, and observed space reaches at least the
  // truncation distance mu in front of every fused surface (fusion writes every voxel of the
  // band from +mu on, see fuse_voxel). Steps of mu/2 through unobserved cells therefore land at
  // least one observed sample in front of the next surface, where the march below takes over.
  const float unobserved_step = fmaxf(min_step, 0.5f * a.geom.truncation / (dlen * a.geom.voxel_size));
  const float step_per_sdf = 0.8f / (dlen * a.geom.voxel_size);  // see the step below
  const vec3 inv_d{1.f / d.x, 1.f / d.y, 1.f / d.z};             // +-inf on an axis d does not move along
  constexpr int kRefineSteps = 3;
  float z_prev = 0.f, f_prev = 0.f;
  bool have_prev = false, prev_near = false;     // prev_near: the last sample's block is near a surface
  int refine = -1;                               // -1: marching; else regula falsi steps taken
  float ta = 0.f, fa = 0.f, tb = 0.f, fb = 0.f;  // the bracket: fa > 0 at ta, fb <= 0 at tb
  for (int it = 0; refine >= 0 || (it < 8192 && z < z_end); ++it) {
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
      z = max_of(block_exit(o, d, inv_d, b), z) + min_step * 0.1f;
      have_prev = false;
      continue;
    }
    if (!sampled) {
      z += unobserved_step;
      have_prev = false;
      continue;
    }
    if (have_prev && f_prev > 0.f && f <= 0.f) {
      ta = z_prev, fa = f_prev, tb = z, fb = f, refine = 0;
      z = ta + (tb - ta) * fa / (fa - fb);
      continue;
    }
    z_prev = z, f_prev = f, have_prev = true, prev_near = near;
    // |TSDF| is at most about the distance to the nearest zero crossing (projective distances
    // over-estimate at grazing angles, hence the 0.8), so stepping that far along the ray (|d| s
    // metres per unit of z) cannot jump over one: truncation-sized steps in the band's free-space
    // side (and through the back of a surface a ray enters from behind), shrinking to half a
    // voxel at the surface.
    z += max_of(fabsf(f) * step_per_sdf, min_step);
  }
  if (refine < 0) return false;
  *hit = z;
  return true;
}

template <class Acc>
SEAMLESS_HD inline void raycast_pixel(const Acc& a, int x, int y, const Intrinsics& K, const SE3& world_T_camera,
                                      float min_depth, float max_depth, const RaycastOutput& out,
                                      const RayIntervals& iv) {
  const VoxelGeometry& g = a.geom;
  // Ray in voxel units, parametrised by camera depth z: point(z) = o + d z.
  vec3 dir_c = K.unproject(static_cast<float>(x), static_cast<float>(y), 1.f);
  vec3 o = g.to_voxel(world_T_camera.t);
  vec3 d = world_T_camera.rotate(dir_c) / g.voxel_size;
  const float min_step = 0.5f / length(d);  // half a voxel
  float z = min_depth, z_end = max_depth;
  if (iv.bits) {  // march only where blocks are (Niessner section 4.3); no block here: no ray
    const std::int64_t t = iv.tile_of(x, y);
    const float z_near = bits_float(iv.bits[2 * t]), z_far = bits_float(iv.bits[2 * t + 1]);
    z = fmaxf(z, z_near - min_step), z_end = z_far > 0.f ? fminf(z_end, z_far + min_step) : 0.f;
  }
  BlockCache c;
  float zh = 0.f, fh = 0.f;
  vec3 col{0.f, 0.f, 0.f}, vw{0.f, 0.f, 0.f};
  if (march_ray(a, o, d, z, z_end, c, &zh)) {
    vec3 qh = o + d * zh;
    if (out.color.data) sample_tsdf(a, qh, c, &fh, &col);  // no colour wanted: no ninth sample
    vw = g.to_world(qh);
  }
  out.depth(x, y) = zh;  // each output written once; zero where no hit
  out.vertex(x, y) = vw;
  if (out.color.data)
    out.color(x, y) = {static_cast<std::uint8_t>(col.x + 0.5f), static_cast<std::uint8_t>(col.y + 0.5f),
                       static_cast<std::uint8_t>(col.z + 0.5f)};
}

// Threads take pixels in 8 x 4 groups (one CUDA warp each), which stay inside one interval tile
// and see neighbouring surface points: the rays of a warp march alike instead of diverging along
// a 32-pixel row.
constexpr int kRayGroupW = 8, kRayGroupH = 4;

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

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::raycast(const Exec& ex, Acc a, Intrinsics K, SE3 world_T_camera, float min_depth,
                                     float max_depth, RaycastOutput out, RayIntervals iv) {
  const int w = out.depth.width, h = out.depth.height;
  const int groups_x = (w + kRayGroupW - 1) / kRayGroupW, groups_y = (h + kRayGroupH - 1) / kRayGroupH;
  ex.for_each(static_cast<std::int64_t>(groups_x) * groups_y * kRayGroupW * kRayGroupH,
              [=] SEAMLESS_HD(std::int64_t i) {
                const std::int64_t group = i / (kRayGroupW * kRayGroupH);
                const int lane = static_cast<int>(i % (kRayGroupW * kRayGroupH));
                const int x = static_cast<int>(group % groups_x) * kRayGroupW + lane % kRayGroupW;
                const int y = static_cast<int>(group / groups_x) * kRayGroupH + lane / kRayGroupW;
                if (x < w && y < h) raycast_pixel(a, x, y, K, world_T_camera, min_depth, max_depth, out, iv);
              });
  // Ten pixel footprints at the hit's depth: surfaces up to ~84 degrees from the view direction
  // keep their neighbours; a jump beyond that is a silhouette.
  const float jump_per_metre = 10.f / fminf(K.fx, K.fy);
  const vec3 eye = world_T_camera.t;
  View2D<const vec3> vtx = out.vertex;
  View2D<const float> depth = out.depth;
  ex.for_each(static_cast<std::int64_t>(w) * h, [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    const float z = depth(x, y);
    out.normal(x, y) = z > 0.f ? vertex_map_normal(vtx, depth, x, y, eye, jump_per_metre * z) : vec3{0.f, 0.f, 0.f};
  });
}

}  // namespace seamless::kernels
