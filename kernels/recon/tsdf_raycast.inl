// Kernel bodies for raycasting in recon/tsdf.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/tsdf.hpp"
#include "kernels/recon/tsdf_march.hpp"
#include "kernels/recon/tsdf_march_simd.hpp"

namespace seamless::kernels {

// Pixel bounding box and camera-depth range of a block's cell box clipped to the depth slab.
struct ScreenBounds {
  float u0 = 1e30f, u1 = -1e30f, v0 = 1e30f, v1 = -1e30f, z0 = 1e30f, z1 = -1e30f;
  SEAMLESS_HD void add(vec3 p, const Intrinsics& K) {
    vec2 uv = K.project(p);
    u0 = min_of(uv.x, u0), u1 = max_of(uv.x, u1), v0 = min_of(uv.y, v0), v1 = max_of(uv.y, v1);
    z0 = min_of(p.z, z0), z1 = max_of(p.z, z1);
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
                                                 BlockWindow w, const std::int32_t* surface, std::int32_t* near,
                                                 SlotRange slots) {
  const SE3 camera_T_world = world_T_camera.inverse();
  const float zn = fmaxf(min_depth, 1e-3f);
  ex.for_each(slots.threads(t), [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t s = slots.slot(i);
    if (s < 0) return;
    HashKey k = t.keys[s];
    const std::int32_t block = t.values[s];
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
    ScreenBounds sb;
    if (!block_screen_bounds(unpack_block(k), geom, K, camera_T_world, zn, max_depth, &sb)) return;
    // Rays go through pixel centres: pixel x can meet the box only if u0 <= x <= u1. Rounding
    // outwards keeps the splat conservative.
    if (sb.u1 < 0.f || sb.v1 < 0.f || sb.u0 > K.width - 1.f || sb.v0 > K.height - 1.f) return;
    const int x0 = static_cast<int>(floorf(max_of(sb.u0, 0.f))),
              x1 = static_cast<int>(ceilf(min_of(sb.u1, K.width - 1.f)));
    const int y0 = static_cast<int>(floorf(max_of(sb.v0, 0.f))),
              y1 = static_cast<int>(ceilf(min_of(sb.v1, K.height - 1.f)));
    const std::int32_t z_near = float_bits(sb.z0), z_far = float_bits(sb.z1);
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

// Threads take pixels in 8 x 4 groups (one CUDA warp each), which stay inside one interval tile
// and see neighbouring surface points: the rays of a warp march alike instead of diverging along
// a 32-pixel row.
constexpr int kRayGroupW = 8, kRayGroupH = 4;

template <Executor Exec, class Acc>
void TsdfRaycast<Exec, Acc>::raycast(const Exec& ex, Acc a, Intrinsics K, SE3 world_T_camera, float min_depth,
                                     float max_depth, RaycastOutput out, RayIntervals iv) {
  const int w = out.depth.width, h = out.depth.height;
  const int groups_x = (w + kRayGroupW - 1) / kRayGroupW, groups_y = (h + kRayGroupH - 1) / kRayGroupH;
  const std::int64_t groups = static_cast<std::int64_t>(groups_x) * groups_y;
  bool marched = false;
#if !defined(__CUDACC__)
  // The CPU (with AVX2 and the block window) takes a row of a group at a time, its 8 rays marched
  // on SIMD lanes: the same samples and hits as raycast_pixel's (tsdf_march_simd.hpp).
  if constexpr (Exec::device == Device::CPU && std::is_same_v<Acc, WindowedHashAccess>) {
    if (simd::cpu_simd() && simd_marchable(a)) {
      static_assert(kRayGroupW == 8);  // a row of a group: the 8 lanes
      ex.for_each(groups * kRayGroupH, [=](std::int64_t i) {
        const std::int64_t group = i / kRayGroupH;
        const int x0 = static_cast<int>(group % groups_x) * kRayGroupW;
        const int y = static_cast<int>(group / groups_x) * kRayGroupH + static_cast<int>(i % kRayGroupH);
        if (y >= h) return;
        const int n = w - x0 < kRayGroupW ? w - x0 : kRayGroupW;
        PixelRay r[kRayGroupW];
        bool hit[kRayGroupW];
        float zh[kRayGroupW];
        detail::march_row_simd(a, x0, y, n, K, world_T_camera, min_depth, max_depth, iv, r, hit, zh);
        BlockCache c;
        for (int l = 0; l < n; ++l) write_pixel(a, x0 + l, y, r[l], hit[l], zh[l], c, out);
      });
      marched = true;
    }
  }
#endif
  if (!marched)
    ex.for_each(groups * kRayGroupW * kRayGroupH, [=] SEAMLESS_HD(std::int64_t i) {
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
#if !defined(__CUDACC__)
  if constexpr (Exec::device == Device::CPU)
    if (simd::cpu_simd()) {  // 8 pixels of a row at a time: the same normals bit for bit (tsdf_march_simd.hpp)
      const int runs = (w + kRayGroupW - 1) / kRayGroupW;
      ex.for_each(static_cast<std::int64_t>(runs) * h, [=](std::int64_t i) {
        const int x0 = static_cast<int>(i % runs) * kRayGroupW, y = static_cast<int>(i / runs);
        detail::normals_row_simd(vtx, depth, x0, y, w - x0 < kRayGroupW ? w - x0 : kRayGroupW, eye, jump_per_metre,
                                 out.normal);
      });
      return;
    }
#endif
  ex.for_each(static_cast<std::int64_t>(w) * h, [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    out.normal(x, y) = pixel_normal(vtx, depth, x, y, eye, jump_per_metre);
  });
}

}  // namespace seamless::kernels
