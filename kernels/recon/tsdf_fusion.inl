// Kernel bodies for per-frame fusion in recon/tsdf.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/tsdf.hpp"
#if !defined(__CUDACC__)
#include "kernels/recon/tsdf_fusion_simd.hpp"
#endif

namespace seamless::kernels {

// Claims block b for this frame and gives its key a block from the pool if it has none. The
// value goes -1 -> -2 (being filled, by exactly one thread) -> block index, or back to -1 when the
// pool is empty: the key then stays in the table without a block, ignored by every reader, and
// the retry after growing the pool fills it. (Tombstoning it instead would make every later
// attempt on the same key claim a fresh slot.)
SEAMLESS_HD inline void allocate_block(HashTableView t, const std::int32_t* free_list, HashCounters* c, int3 b) {
  if (!block_in_range(b)) return;
  std::int32_t slot = -1;
  int probes = 0;
  InsertResult r = t.insert(pack_block(b), &slot, &probes);
  if (r == InsertResult::Full) {
    atomic_add(&c->probe_failures, 1);
    return;
  }
  if (r == InsertResult::Inserted) {
    atomic_add(&c->inserted, 1);
    if (probes > 0) atomic_add(&c->collisions, 1);
  }
  if (atomic_load(&t.values[slot]) != -1 || atomic_cas(&t.values[slot], -1, -2) != -1) return;
  std::int32_t block = pool_pop(c, free_list);
  atomic_exch(&t.values[slot], block < 0 ? -1 : block);
  if (block < 0) atomic_add(&c->pool_failures, 1);
}

template <Executor Exec>
void TsdfFusion<Exec>::allocate_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                                       HashCounters* counters, FrameInput in, VoxelGeometry geom, DepthTiles tiles,
                                       BlockWindow known) {
  const int w = in.depth.width;
  // Pixel (x, y) with its reading d and the walk over its band's blocks: raises its tile, then
  // claims each block of the walk.
  auto claim = [=] SEAMLESS_HD(int x, int y, float d, const BlockWalk& walk) {
    if (tiles.zmax) {  // the plain read spares most atomics once the tile holds its far reading
      std::int32_t* tile = tiles.zmax + tiles.tile_of(x, y);
      if (float_bits(d) > atomic_load(tile)) atomic_max(tile, float_bits(d));
    }
    walk_blocks(walk, [&](int3 blk) {
      const std::int64_t e = known.index ? known.entry(blk) : -1;
      if (e >= 0 && known.index[e] >= 0) return;  // allocated before this frame
      allocate_block(t, free_list.data, counters, blk);
    });
  };
#if !defined(__CUDACC__)
  // The CPU with AVX2 sets up the walks of 8 pixels of a row at once (tsdf_fusion_simd.hpp: the
  // same walks bit for bit), then walks them one by one.
  if constexpr (Exec::device == Device::CPU)
    if (simd::cpu_simd()) {
      constexpr int kLanes = detail::kBandLanes;
      const int groups = (w + kLanes - 1) / kLanes;
      ex.for_each(static_cast<std::int64_t>(groups) * in.depth.height, [=](std::int64_t i) {
        const int x0 = static_cast<int>(i % groups) * kLanes, y = static_cast<int>(i / groups);
        BlockWalk walks[kLanes];
        const int lanes = detail::band_walks_simd(in, geom, x0, y, walks);
        for (int l = 0; l < kLanes; ++l)
          if (lanes >> l & 1) claim(x0 + l, y, in.depth(x0 + l, y), walks[l]);
      });
      return;
    }
#endif
  ex.for_each(in.depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    const float d = in.depth(x, y);
    if (d >= in.min_depth && d <= in.max_depth) claim(x, y, d, band_walk(in, geom, x, y, d));
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::allocate_free_space(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                                           HashCounters* counters, FrameInput in, VoxelGeometry geom) {
  const int s = free_space_stride(in.K.fx, in.max_depth, geom), w = in.depth.width;
  const int nx = (w + s - 1) / s, ny = (in.depth.height + s - 1) / s;
  const float mu = geom.truncation;
  const float to_block = 1.f / (geom.voxel_size * kBlockSide);
  ex.for_each(static_cast<std::int64_t>(nx) * ny, [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % nx) * s, y = static_cast<int>(i / nx) * s;
    const float d = in.depth(x, y);
    if (!(d >= in.min_depth && d <= in.max_depth)) return;
    const vec3 p = in.K.unproject(static_cast<float>(x), static_cast<float>(y), d);
    // From min_depth along the ray (the sensor reads nothing nearer) to where allocate_blocks'
    // band begins; the segments overlap by the block they share.
    const float from = in.min_depth / d, to = 1.f - mu / length(p);
    if (!(to > from)) return;
    const vec3 a = (in.world_T_camera * (p * from) - geom.origin) * to_block;
    const vec3 b = (in.world_T_camera * (p * to) - geom.origin) * to_block;
    walk_blocks(block_walk(a, b), [&](int3 blk) { allocate_block(t, free_list.data, counters, blk); });
  });
}

// Does some tile in pixels [u0, u1] x [v0, v1] hold a depth reading at or beyond z? A voxel is
// changed only where the reading d at its pixel has d - z_voxel >= -mu (fuse_voxel).
SEAMLESS_HD inline bool tiles_reach(const DepthTiles& t, int u0, int u1, int v0, int v1, float z) {
  const std::int32_t zb = float_bits(max_of(z, 0.f));
  for (int ty = v0 / t.tile; ty <= v1 / t.tile; ++ty)
    for (int tx = u0 / t.tile; tx <= u1 / t.tile; ++tx)
      if (t.zmax[t.tile_of(tx * t.tile, ty * t.tile)] >= zb) return true;
  return false;
}

// Could the frame change block b? It must project into the image in front of the camera within
// max_depth+mu and, with tiles, some tile under it must have a reading no more than mu in front of
// its nearest point. The test uses the block's box in voxel units, [8b, 8b + 8] per axis, which
// holds its voxel centres (8b .. 8b + 7) and is the box allocate_blocks assigns points to. So the
// voxels, and any depth ray that allocated the block this frame (which must list it, so that a
// block whose voxels that frame leaves empty is freed as without tiles), project into the rounded
// bounding box of the box corners' projections, at depths >= the corners' smallest.
SEAMLESS_HD inline bool block_maybe_visible(int3 b, const FrameInput& in, const SE3& camera_T_world,
                                            const VoxelGeometry& geom, const DepthTiles& tiles = {}) {
  float umin = 1e30f, umax = -1e30f, vmin = 1e30f, vmax = -1e30f, zmin = 1e30f;
  bool behind = false;
  for (int k = 0; k < 8; ++k) {
    int3 g{b.x * 8 + (k & 1) * 8, b.y * 8 + ((k >> 1) & 1) * 8, b.z * 8 + (k >> 2) * 8};
    vec3 pc = camera_T_world * geom.to_world(to_vec3(g));
    zmin = min_of(pc.z, zmin);
    if (pc.z <= 1e-4f) {
      behind = true;
      continue;
    }
    vec2 uv = in.K.project(pc);
    umin = min_of(uv.x, umin), umax = max_of(uv.x, umax), vmin = min_of(uv.y, vmin), vmax = max_of(uv.y, vmax);
  }
  if (zmin > in.max_depth + geom.truncation) return false;
  if (behind) return umax > -1e29f;  // straddles the camera plane: keep if any corner is in front
  if (!(umax >= -0.5f && umin <= in.depth.width - 0.5f && vmax >= -0.5f && vmin <= in.depth.height - 0.5f))
    return false;
  if (!tiles.zmax) return true;
  const float wl = in.depth.width - 1.f, hl = in.depth.height - 1.f;  // clamped, then rounded as fuse_voxel rounds
  const int u0 = static_cast<int>(floorf(max_of(umin, 0.f) + 0.5f)),
            u1 = static_cast<int>(floorf(min_of(umax, wl) + 0.5f));
  const int v0 = static_cast<int>(floorf(max_of(vmin, 0.f) + 0.5f)),
            v1 = static_cast<int>(floorf(min_of(vmax, hl) + 0.5f));
  return tiles_reach(tiles, u0, u1, v0, v1, zmin - geom.truncation);
}

template <Executor Exec> void TsdfFusion<Exec>::clear_depth_tiles(const Exec& ex, DepthTiles tiles) {
  ex.for_each(tiles.count(), [=] SEAMLESS_HD(std::int64_t i) { tiles.zmax[i] = 0; });
}

template <Executor Exec>
void TsdfFusion<Exec>::find_visible_blocks(const Exec& ex, HashTableView t, HashCounters* counters, FrameInput in,
                                           VoxelGeometry geom, View<std::int32_t> visible_slots,
                                           View<std::int32_t> keep, DepthTiles tiles, std::int32_t* surface,
                                           View<std::int32_t> live) {
  const SE3 camera_T_world = in.world_T_camera.inverse();
  ex.for_each(static_cast<std::int64_t>(t.mask) + 1, [=] SEAMLESS_HD(std::int64_t i) {
    if (i == 0 && counters->free_top < 0) counters->free_top = 0;  // after failed pops
    HashKey k = t.keys[i];
    if (!is_live_key(k) || t.values[i] < 0) return;
    if (live.data) live[atomic_add(&counters->listed, 1)] = static_cast<std::int32_t>(i);
    if (!block_maybe_visible(unpack_block(k), in, camera_T_world, geom, tiles)) return;
    const int j = atomic_add(&counters->visible, 1);
    visible_slots[j] = static_cast<std::int32_t>(i);
    if (keep.data) keep[j] = 0;
    if (surface) surface[t.values[i]] = 0;
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::sort_visible_by_block(const Exec& ex, HashTableView t, View<std::int32_t> slots,
                                             std::int64_t count, View<std::int32_t> block_keys, int key_bits) {
  ex.for_each(count, [=] SEAMLESS_HD(std::int64_t i) { block_keys[i] = t.values[slots[i]]; });
  ex.sort_by_key(block_keys.data, slots.data, count, key_bits);
}

// Sets a keep flag; the read first spares the atomic when another voxel already set it.
SEAMLESS_HD inline void set_keep(std::int32_t* flag) {
  if (atomic_load(flag) == 0) atomic_exch(flag, 1);
}

// Free-space carving (after ReFusion, Palazzolo et al. 2019, section III-D): the voxel
// lies more than in.carve in front of the reading at its pixel and of the 3x3 readings around it,
// so the ray saw through it: whatever surface it held (a person who stood there) is gone. The
// running average alone would need as many free observations as the voxel had weight (up to
// max_weight frames); the reset takes one. The neighbours keep a voxel at an object's silhouette,
// whose pixel may read the background behind, from being carved by its rounding.
SEAMLESS_HD inline bool carved(const FrameInput& in, int u, int v, float z) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      if (!in.depth.inside(u + dx, v + dy)) return false;
      const float d = in.depth(u + dx, v + dy);
      if (!(d >= in.min_depth && d <= in.max_depth) || d - z <= in.carve) return false;
    }
  return true;
}

// Weighted running average of the truncated signed distance (Curless & Levoy 1996; KinectFusion
// eq. 11-13) with the weight capped at max_weight so the model can follow change. The distance is
// projective (along z), as in KinectFusion and Niessner; colour is averaged only near the surface.
// The average is kept in snorm16 steps, rounded to nearest (fuse_tsdf, Voxel). v_color: the
// voxel's colour (nullptr: no colour fused).
SEAMLESS_HD inline void fuse_voxel(Voxel& v, uchar3* v_color, vec3 p_world, const FrameInput& in,
                                   const SE3& camera_T_world, float mu, float max_weight) {
  vec3 pc = camera_T_world * p_world;
  if (pc.z <= 0.f) return;
  vec2 uv = in.K.project(pc);
  int u = floor_int(uv.x + 0.5f), w = floor_int(uv.y + 0.5f);
  if (!in.depth.inside(u, w)) return;
  float d = in.depth(u, w);
  if (!(d >= in.min_depth && d <= in.max_depth)) return;
  float sdf = d - pc.z;
  if (sdf < -mu) return;  // occluded: behind the surface by more than the truncation
  if (in.carve > 0.f && sdf > in.carve && carved(in, u, w, pc.z)) {
    v = make_voxel(mu, mu, 1.f);  // what a voxel never seen before holds after this frame: free, weight 1
    return;
  }
  const float wt = voxel_weight(v);
  fuse_tsdf(v, min_of(sdf, mu), mu, max_weight);
  if (v_color && in.rgb.data && sdf < mu) *v_color = blend_color(*v_color, in.rgb(u, w), wt);
}

template <Executor Exec>
void TsdfFusion<Exec>::fuse_hash_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots,
                                        std::int64_t count, Voxel* voxels, uchar3* colors, FrameInput in,
                                        VoxelGeometry geom, float max_weight, View<std::int32_t> keep, float keep_below,
                                        SurfaceFlags surface) {
  const SE3 camera_T_world = in.world_T_camera.inverse();
#if !defined(__CUDACC__)
  // The CPU: a work item per layer of a block (its 64 voxels at one z), fused a row (8 voxels
  // along x) at a time on 8 SIMD lanes, the same values as the loop below
  // (tsdf_fusion_simd.hpp). Carving reads 9 pixels a voxel and takes the loop below.
  if constexpr (Exec::device == Device::CPU) {
    if (in.carve <= 0.f && simd::cpu_simd()) {
      const FuseRowFrame f{in,
                           camera_T_world,
                           geom,
                           max_weight,
                           keep_below,
                           surface.below,
                           keep.data != nullptr,
                           surface.flag != nullptr};
      ex.for_each(count * kBlockSide, [=](std::int64_t i) {
        const std::int64_t j = i / kBlockSide;
        const std::int32_t slot = slots[j];
        const std::int32_t block = t.values[slot];
        if (block < 0) return;
        const int z = static_cast<int>(i % kBlockSide);
        const std::int64_t first = static_cast<std::int64_t>(block) * kBlockVoxels + z * kBlockSide * kBlockSide;
        const int flags = detail::fuse_layer_simd(f, unpack_block(t.keys[slot]), z, voxels + first,
                                                  colors ? colors + first : nullptr);
        if (flags & kRowKeeps) set_keep(&keep[j]);
        if (flags & kRowNearSurface) set_keep(&surface.flag[block]);
      });
      return;
    }
  }
#endif
  // One thread per column of a block (its 8 voxels along z, 64 threads a block): the block's slot,
  // index and key are read once per column instead of once per voxel, and the column's 8 voxels
  // are independent work in one thread, so their loads can be in flight together. A warp's 32
  // columns are 32 consecutive voxels of each z layer, so its loads stay contiguous. Every voxel
  // is computed exactly as one thread per voxel computed it.
  constexpr int kColumns = kBlockSide * kBlockSide;
  ex.for_each(count * kColumns, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t j = i / kColumns;
    const std::int32_t slot = slots[j];
    const std::int32_t block = t.values[slot];
    if (block < 0) return;
    const int3 b = unpack_block(t.keys[slot]);
    const int column = static_cast<int>(i % kColumns);
    const std::int64_t first = static_cast<std::int64_t>(block) * kBlockVoxels + column;
    Voxel* v = voxels + first;
    uchar3* vc = colors ? colors + first : nullptr;
    // The column's x and y are fixed: written so, the compiler computes their part of the
    // transform (to_world's, and the x and y products of each row's dot product, summed first)
    // once a column instead of once a voxel. The same operations in the same order: same values.
    const int3 l = local_coords(column);
    bool kept = false, surface_near = false;
#pragma unroll
    for (int z = 0; z < kBlockSide; ++z) {
      const vec3 g{float(b.x * 8 + l.x), float(b.y * 8 + l.y), float(b.z * 8 + z)};
      Voxel& vz = v[kColumns * z];
      fuse_voxel(vz, vc ? vc + kColumns * z : nullptr, geom.to_world(g), in, camera_T_world, geom.truncation,
                 max_weight);
      kept = kept || (keep.data && voxel_keeps_block(vz, keep_below, geom.truncation));
      surface_near = surface_near || (surface.flag && voxel_keeps_block(vz, surface.below, geom.truncation));
    }
    if (kept) set_keep(&keep[j]);
    if (surface_near) set_keep(&surface.flag[block]);
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::fuse_dense_blocks(const Exec& ex, DenseAccess grid, FrameInput in, float max_weight,
                                         bool color) {
  const SE3 camera_T_world = in.world_T_camera.inverse();
  const int n = grid.blocks_per_side;
  const std::int64_t blocks = static_cast<std::int64_t>(n) * n * n;
  ex.for_each(blocks * kBlockVoxels, [=] SEAMLESS_HD(std::int64_t i) {
    std::int64_t block = i / kBlockVoxels;
    int li = static_cast<int>(i % kBlockVoxels);
    int3 b{static_cast<int>(block % n), static_cast<int>((block / n) % n), static_cast<int>(block / n / n)};
    int3 l = local_coords(li);
    vec3 g{float(b.x * 8 + l.x), float(b.y * 8 + l.y), float(b.z * 8 + l.z)};
    fuse_voxel(grid.voxels[i], color ? grid.colors + i : nullptr, grid.geom.to_world(g), in, camera_T_world,
               grid.geom.truncation, max_weight);
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::mark_kept_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots,
                                        std::int64_t count, const Voxel* voxels, View<std::int32_t> keep,
                                        float keep_below, float mu) {
  ex.for_each(count * kBlockVoxels, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t j = i / kBlockVoxels;
    std::int32_t block = t.values[slots[j]];
    if (block < 0) return;
    if (voxel_keeps_block(voxels[static_cast<std::int64_t>(block) * kBlockVoxels + i % kBlockVoxels], keep_below, mu))
      set_keep(&keep[j]);
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::mark_surface_blocks(const Exec& ex, View<const std::int32_t> blocks, const Voxel* voxels,
                                           SurfaceFlags surface, float mu) {
  ex.for_each(blocks.size, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int32_t block = blocks[i];
    if (block < 0) return;
    const Voxel* v = voxels + static_cast<std::int64_t>(block) * kBlockVoxels;
    std::int32_t flag = 0;
    for (int k = 0; k < kBlockVoxels && !flag; ++k) flag = voxel_keeps_block(v[k], surface.below, mu) ? 1 : 0;
    surface.flag[block] = flag;
  });
}

template <Executor Exec>
void TsdfFusion<Exec>::remove_unkept_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots,
                                            std::int64_t count, View<const std::int32_t> keep, Voxel* voxels,
                                            uchar3* colors, View<std::int32_t> free_list, HashCounters* counters) {
  // kParts threads per block, each zeroing 512 / kParts voxels: one thread clearing a whole block
  // (3.5 KiB with its colours) would hold up the kernel. Part 0 also frees the slot and the block; the block is not
  // handed out again before the next allocation kernel, after this one has finished. The slot's
  // value is left as it is (as hash_erase does): nobody reads the value of a tombstone.
  constexpr int kParts = 8, kPerPart = kBlockVoxels / kParts;
  ex.for_each(count * kParts, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t j = i / kParts;
    const int part = static_cast<int>(i % kParts);
    if (keep[j]) return;
    std::int32_t slot = slots[j];
    std::int32_t block = t.values[slot];
    if (block < 0) return;
    const std::int64_t first = static_cast<std::int64_t>(block) * kBlockVoxels + part * kPerPart;
    for (int k = 0; k < kPerPart; ++k) voxels[first + k] = Voxel{0, 0}, colors[first + k] = uchar3{0, 0, 0};
    if (part != 0) return;
    atomic_exch(&t.keys[slot], kTombstone);
    pool_push(counters, free_list.data, block);
    atomic_add(&counters->tombstones, 1);
    atomic_add(&counters->removed, 1);
  });
}

}  // namespace seamless::kernels
