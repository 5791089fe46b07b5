// TSDF kernels over voxel blocks (voxel hashing after Niessner et al. 2013; fusion after Curless &
// Levoy 1996 / KinectFusion, Newcombe et al. 2011, section 3.3). The per-element pieces live in
// voxel_hash.hpp; these are the kernel families, each written once over the executor.
#pragma once
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "core/exec.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "core/view.hpp"
#include "kernels/recon/voxel_hash.hpp"

namespace seamless::kernels {

template <Executor Exec> struct VoxelHash {
  // --- hash table maintenance (family recon/voxel_hash) ------------------------------------------
  // Empties every slot (keys -> empty, values -> -1).
  static void hash_clear(const Exec& ex, HashTableView t);

  // Free list = 0..n-1, all counters zero, free_top = n.
  static void pool_reset(const Exec& ex, View<std::int32_t> free_list, HashCounters* counters);

  // Puts blocks first..first+n-1 on the free list (after the pool grew); free_top += n.
  static void pool_append(const Exec& ex, View<std::int32_t> free_list, HashCounters* counters, std::int32_t first,
                          std::int32_t n);

  // Zeroes the per-frame fields of the counters (inserted, collisions, failures, visible, removed,
  // listed).
  static void reset_frame_counters(const Exec& ex, HashCounters* counters);

  // Concurrent insert of keys (duplicates allowed); slot_out[i] = slot, result_out[i] = InsertResult.
  // A newly inserted key gets values[slot] = value_in[i] (or -1 when value_in is empty).
  static void hash_insert(const Exec& ex, HashTableView t, View<const HashKey> keys, View<const std::int32_t> value_in,
                          View<std::int32_t> slot_out, View<std::int32_t> result_out, HashCounters* counters);

  // slot_out[i] = slot of keys[i] or -1.
  static void hash_find(const Exec& ex, HashTableView t, View<const HashKey> keys, View<std::int32_t> slot_out);

  // Tombstones every key present; slot_out[i] = freed slot or -1 (absent, or erased by a duplicate).
  static void hash_erase(const Exec& ex, HashTableView t, View<const HashKey> keys, View<std::int32_t> slot_out,
                         HashCounters* counters);

  // Slots holding a live key with a block, in slot order (deterministic); returns how many. flags
  // must hold one int per slot (scratch).
  static std::int64_t hash_live_slots(const Exec& ex, HashTableView t, View<std::int32_t> flags,
                                      View<std::int32_t> slots_out);

  // Slots of the live blocks whose centre lies farther than radius from center (both in voxel
  // units), in slot order; returns how many (streaming out, Niessner section 5). flags as above.
  static std::int64_t hash_slots_beyond(const Exec& ex, HashTableView t, vec3 center, float radius,
                                        View<std::int32_t> flags, View<std::int32_t> slots_out);

  // Inserts each key (distinct, absent) with a block popped from the pool: blocks_out[i] = the block,
  // or -1 when the key was already present or no slot (probe_failures) or block (pool_failures)
  // was left; a key left without a block is tombstoned again, so it can be inserted later.
  static void insert_with_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                                 HashCounters* counters, View<const HashKey> keys, View<std::int32_t> blocks_out);

  // Copies (key, value) of the given slots out (for rehashing and host inspection).
  static void hash_gather(const Exec& ex, HashTableView t, View<const std::int32_t> slots, View<HashKey> keys_out,
                          View<std::int32_t> values_out);

  // Copies whole blocks out of / into the pools of voxels and colours: out[i*512 + k] =
  // pool[blocks[i]*512 + k] and back, the same for colours (host download, streaming, dense <->
  // hash conversion); scatter skips blocks[i] < 0.
  static void gather_blocks(const Exec& ex, const Voxel* pool, const uchar3* colors, View<const std::int32_t> blocks,
                            View<Voxel> out, View<uchar3> out_colors);

  static void scatter_blocks(const Exec& ex, Voxel* pool, uchar3* colors, View<const std::int32_t> blocks,
                             View<const Voxel> in, View<const uchar3> in_colors);
};

// --- per-frame fusion (family recon/tsdf_fusion) -----------------------------------------------
struct FrameInput {
  View2D<const float> depth;  // metres, 0 = no reading
  View2D<const uchar3> rgb;   // same size as depth, or data == nullptr for none
  Intrinsics K;
  SE3 world_T_camera;
  float min_depth = 0.3f, max_depth = 4.f;
  // Free-space carving (dynamic.carve_truncations * truncation, metres; 0: off): fuse_voxel resets
  // a voxel this far in front of the measurement to free space (docs/DYNAMIC.md).
  float carve = 0.f;
};

// An image cut into tile x tile pixel tiles, row-major (the last row and column may be partial):
// the layout of the per-tile arrays below (DepthTiles, RayIntervals).
struct TileGrid {
  int tile = 8, tiles_x = 0, tiles_y = 0;
  static TileGrid covering(int width, int height, int tile) {
    return {tile, (width + tile - 1) / tile, (height + tile - 1) / tile};
  }
  SEAMLESS_HD std::int64_t count() const { return static_cast<std::int64_t>(tiles_x) * tiles_y; }
  SEAMLESS_HD std::int64_t tile_of(int x, int y) const {
    return static_cast<std::int64_t>(y / tile) * tiles_x + x / tile;
  }
};

// The farthest valid depth reading of every tile of a frame, as float_bits (non-negative floats
// order as their bits; 0: no reading). A voxel behind it by more than the truncation cannot be
// changed by the frame. allocate_blocks fills it (it reads every pixel anyway) after
// clear_depth_tiles.
struct DepthTiles : TileGrid {
  std::int32_t* zmax = nullptr;  // nullptr: no tiles, nothing is culled
};
// The slots a pass over the live blocks visits: every slot of the table, or the live slots that
// find_visible_blocks listed when `listed` is set. The table keeps its fill at or below a half and
// typically holds a live block every 8-10 slots, so a pass over it gives a few of a CUDA warp's 32
// threads a block's work while the warp runs as long as one of them; over the list every thread
// has a block.
struct SlotRange {
  const std::int32_t* listed = nullptr;  // nullptr: every slot of the table
  const int* count = nullptr;            // how many are listed (where the kernels run)
  std::int64_t bound = 0;                // at least *count (the pool's size): the threads launched
  std::int64_t threads(const HashTableView& t) const { return listed ? bound : static_cast<std::int64_t>(t.mask) + 1; }
  // Thread i's slot; -1: none.
  SEAMLESS_HD std::int64_t slot(std::int64_t i) const { return !listed ? i : i < *count ? listed[i] : -1; }
};

// A block is worth keeping while one of its voxels is observed (weight > 0) and near a surface
// (|sdf| < keep_below, metres; mu: the truncation); a block of free space or never-observed voxels
// can go. (A volume that stores free space passes the largest float: every observed block stays.)
SEAMLESS_HD inline bool voxel_keeps_block(const Voxel& v, float keep_below, float mu) {
  return voxel_observed(v) && fabsf(voxel_sdf(v, mu)) < keep_below;
}

// A voxel's colour after one more observation c: fusion's weighted running average (Curless & Levoy
// 1996; KinectFusion eq. 11-13) with the voxel's weight wt before it, rounded to a byte. (The
// distance's running average is fuse_tsdf, voxel_hash.hpp.)
SEAMLESS_HD inline uchar3 blend_color(uchar3 old, uchar3 c, float wt) {
  auto avg = [&](std::uint8_t o, std::uint8_t obs) {
    return static_cast<std::uint8_t>(min_of((float(o) * wt + float(obs)) / (wt + 1.f) + 0.5f, 255.f));
  };
  return {avg(old.x, c.x), avg(old.y, c.y), avg(old.z, c.z)};
}

// The surface flag of each block of the pool (docs/DYNAMIC.md "The surface flag"): 1
// while one of its voxels is observed and near a surface (voxel_keeps_block with the band's
// threshold below = 0.999 truncation, whatever the garbage collection keeps), else 0. It is the
// band-only volume's garbage collection's decision (Niessner et al. 2013), kept for the blocks
// that a volume storing free space keeps anyway (ReFusion, Palazzolo et al. 2019), so that the
// raycast can pass through them as through unallocated space.
struct SurfaceFlags {
  std::int32_t* flag = nullptr;  // one per pool block, by block index; nullptr: not kept
  float below = 0.f;             // metres
};

// A walk over the block grid along a segment a -> b (block units; Amanatides & Woo 1987): from
// block c to block e, stepping s along the axis whose next face comes first (t: the segment's
// parameter at each axis's next face, dt: between faces; inf where the segment does not move
// along the axis). A walk from c to e takes |e - c|_1 steps; n_max only stops one that float
// rounding carries past e (which otherwise ends once t passes 1), and is never below 64, the
// bound of the truncation band's short segments.
struct BlockWalk {
  int3 c, e, s;
  vec3 t, dt;
  int n_max;
};

SEAMLESS_HD inline BlockWalk block_walk(vec3 a, vec3 b) {
  BlockWalk w;
  w.c = floor_to_int(a), w.e = floor_to_int(b);
  const int3 span{w.e.x - w.c.x, w.e.y - w.c.y, w.e.z - w.c.z};
  const int steps =
      (span.x < 0 ? -span.x : span.x) + (span.y < 0 ? -span.y : span.y) + (span.z < 0 ? -span.z : span.z) + 1;
  w.n_max = steps > 64 ? steps : 64;
  const vec3 d = b - a;
  const float inf = 1e30f;
  w.s = {d.x > 0 ? 1 : -1, d.y > 0 ? 1 : -1, d.z > 0 ? 1 : -1};
  w.t = {d.x != 0.f ? ((w.c.x + (w.s.x > 0)) - a.x) / d.x : inf, d.y != 0.f ? ((w.c.y + (w.s.y > 0)) - a.y) / d.y : inf,
         d.z != 0.f ? ((w.c.z + (w.s.z > 0)) - a.z) / d.z : inf};
  w.dt = {d.x != 0.f ? fabsf(1.f / d.x) : inf, d.y != 0.f ? fabsf(1.f / d.y) : inf,
          d.z != 0.f ? fabsf(1.f / d.z) : inf};
  return w;
}

// Visits every block of the walk, in order.
template <class F> SEAMLESS_HD inline void walk_blocks(BlockWalk w, F visit) {
  int3 c = w.c;
  float tx = w.t.x, ty = w.t.y, tz = w.t.z;
  for (int n = 0; n < w.n_max; ++n) {
    visit(c);
    if (c == w.e) return;
    if (tx <= ty && tx <= tz) {
      if (tx > 1.f) return;
      c.x += w.s.x;
      tx += w.dt.x;
    } else if (ty <= tz) {
      if (ty > 1.f) return;
      c.y += w.s.y;
      ty += w.dt.y;
    } else {
      if (tz > 1.f) return;
      c.z += w.s.z;
      tz += w.dt.z;
    }
  }
}

// The walk over the blocks of pixel (x, y)'s truncation band, [d - mu, d + mu] along its ray
// (Niessner section 4.1), d its reading. Voxel g sits at origin + g s and block b holds voxels
// 8b .. 8b + 7, so in block units a world point p lies in block floor((p - origin) / (8 s)).
SEAMLESS_HD inline BlockWalk band_walk(const FrameInput& in, const VoxelGeometry& geom, int x, int y, float d) {
  const vec3 p = in.K.unproject(static_cast<float>(x), static_cast<float>(y), d);
  const float r = geom.truncation / length(p);
  const float to_block = 1.f / (geom.voxel_size * kBlockSide);
  const vec3 a = (in.world_T_camera * (p * (1.f - r)) - geom.origin) * to_block;
  const vec3 b = (in.world_T_camera * (p * (1.f + r)) - geom.origin) * to_block;
  return block_walk(a, b);
}

// Free space in the voxel-hashed volume (docs/DYNAMIC.md "Evidence of free space"): as in
// ReFusion (Palazzolo et al. 2019), the blocks along the whole ray in front of a reading are
// allocated, so fusion stores the free space (+truncation) there, not only the band around the
// surface (Niessner et al. 2013, section 4.1). Only the pixels on a lattice of every stride-th
// pixel of every stride-th row cast such rays: fusion writes every voxel of a block from every
// pixel, so the rays need only hit every block in front of the readings. A block of side L holds a
// ball of diameter L, whose shadow across the rays is a disc of that diameter, and a square lattice
// of spacing g leaves no disc of diameter sqrt(2) g empty: rays at most L / sqrt(2) apart at the
// farthest depth (stride * max_depth / fx <= L / sqrt(2)) hit every block out to it.
SEAMLESS_HD inline int free_space_stride(float fx, float max_depth, const VoxelGeometry& geom) {
  const float s = floorf(kBlockSide * geom.voxel_size * fx / (1.41421356f * max_depth));
  return s > 1.f ? static_cast<int>(s) : 1;
}

template <Executor Exec> struct TsdfFusion {
  static void clear_depth_tiles(const Exec& ex, DepthTiles tiles);

  // Inserts every block that the truncation band [d - mu, d + mu] of each depth ray passes through
  // (Niessner section 4.1), popping a block from the pool for each new key; failures are counted.
  // Raises each tile of `tiles` (when given) to the farthest valid reading in it. `known` (when
  // given) must hold every block of the table inside it (the last raycast's window, no block freed
  // since): a block it holds needs no probe of the table, since its key already has a block; the
  // window's neighbours lie together in memory where the table scatters them.
  static void allocate_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                              HashCounters* counters, FrameInput in, VoxelGeometry geom, DepthTiles tiles = {},
                              BlockWindow known = {});

  // Inserts the blocks in front of the band, from min_depth along the rays of the pixels on a
  // lattice of free_space_stride (above), like allocate_blocks. Run after it (the depth tiles are
  // its): the blocks it adds lie in front of their tiles' readings, so find_visible_blocks lists them.
  static void allocate_free_space(const Exec& ex, HashTableView t, View<const std::int32_t> free_list,
                                  HashCounters* counters, FrameInput in, VoxelGeometry geom);

  // Appends to visible_slots every allocated block that the frame may change (counters->visible is
  // the count) and zeroes its keep flag (keep may be empty) and its block's surface flag (surface
  // may be nullptr; fuse_hash_blocks sets it again): blocks whose voxels may project into the
  // image, less those that tiles (when given) show to be occluded or unobserved. When `live` is
  // given (as many entries as the pool has blocks), the pass also lists every live slot there, in
  // no particular order (counters->listed, zeroed by reset_frame_counters, counts them): the slots
  // a later pass over the live blocks may visit instead of the whole table (SlotRange). Also
  // clamps free_top after a failed allocation pass.
  static void find_visible_blocks(const Exec& ex, HashTableView t, HashCounters* counters, FrameInput in,
                                  VoxelGeometry geom, View<std::int32_t> visible_slots, View<std::int32_t> keep,
                                  DepthTiles tiles = {}, std::int32_t* surface = nullptr, View<std::int32_t> live = {});

  // Reorders the first count visible slots by their block's index in the pool (block_keys:
  // count entries of scratch). Fusing in pool order walks the voxel pool and the depth image with
  // far fewer cache and TLB misses on the CPU than the hash table's slot order (blocks allocated
  // together lie together, and come from neighbouring pixels); the fused values are the same in
  // any order, since every voxel is fused by one thread from its own reading.
  static void sort_visible_by_block(const Exec& ex, HashTableView t, View<std::int32_t> slots, std::int64_t count,
                                    View<std::int32_t> block_keys, int key_bits);

  // Fuses one frame into the listed blocks, one thread per column of 8 voxels, and the frame's colour
  // into colors (nullptr: no colour fused). When keep is not empty, keep[j]
  // becomes 1 if block j still has a voxel near a surface afterwards (voxel_keeps_block), so that
  // finding the empty blocks costs no second pass over the voxels. Likewise surface.flag (when
  // set, and zeroed by find_visible_blocks) of each listed block's pool index, with surface.below.
  static void fuse_hash_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots, std::int64_t count,
                               Voxel* voxels, uchar3* colors, FrameInput in, VoxelGeometry geom, float max_weight,
                               View<std::int32_t> keep, float keep_below, SurfaceFlags surface = {});

  // Fuses one frame into every block of a dense grid.
  static void fuse_dense_blocks(const Exec& ex, DenseAccess grid, FrameInput in, float max_weight, bool color);

  // keep[j] = 1 if listed block j has a voxel that keeps it (the caller zeroes keep), one thread
  // per voxel: the stand-alone version of the marking that fuse_hash_blocks does. mu: the truncation.
  static void mark_kept_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots, std::int64_t count,
                               const Voxel* voxels, View<std::int32_t> keep, float keep_below, float mu);

  // surface.flag[blocks[i]] = whether block blocks[i] (skipped when < 0) has a voxel near a
  // surface, one thread per block: for blocks whose voxels were copied in (streaming). mu: the truncation.
  static void mark_surface_blocks(const Exec& ex, View<const std::int32_t> blocks, const Voxel* voxels,
                                  SurfaceFlags surface, float mu);

  // Frees the listed blocks whose keep flag is 0: zeroes their voxels and colours, tombstones their
  // keys and pushes them on the free list (counters->removed counts). A few threads per block.
  static void remove_unkept_blocks(const Exec& ex, HashTableView t, View<const std::int32_t> slots, std::int64_t count,
                                   View<const std::int32_t> keep, Voxel* voxels, uchar3* colors,
                                   View<std::int32_t> free_list, HashCounters* counters);
};

// --- raycasting (family recon/tsdf_raycast) ----------------------------------------------------
struct RaycastOutput {
  View2D<float> depth;   // camera z of the hit, metres; 0 = no hit
  View2D<vec3> vertex;   // world coordinates; zero where no hit
  View2D<vec3> normal;   // world coordinates, unit, facing the camera; zero where no hit
  View2D<uchar3> color;  // fused colour; zero where no hit
};
// Ray intervals (Niessner section 4.3): the image is cut into tile x tile pixel tiles, and each
// tile holds the camera-depth range [near, far] covered by the blocks whose boxes project onto it,
// so that a ray marches only from its tile's near to its far depth and a tile without blocks casts
// no ray at all. Depths are stored as the bits of positive floats, which order like the floats,
// so integer atomic_min / atomic_max splat them on both backends.
struct RayIntervals : TileGrid {
  std::int32_t* bits = nullptr;  // 2 per tile: [2t] near, [2t+1] far; nullptr: no intervals
};
constexpr std::int32_t kEmptyNear = 0x7f800000;  // +infinity
constexpr std::int32_t kEmptyFar = 0;            // +0: no block splatted

// Blocks without a surface (docs/DYNAMIC.md "The surface flag"). A volume that stores
// free space keeps the blocks in front of the surfaces, whose voxels all hold +truncation; the
// raycast would march through them in truncation-sized steps where it skips an unallocated block
// whole. The trilinear sample in the cell of voxel g0 reads the voxels g0 + {0,1}^3, which lie in
// block b = g0 / 8 and in b + {0,1}^3 when g0 is on b's upper faces. So block b is *near a
// surface* when it or one of those 7 upper neighbours has its surface flag set (SurfaceFlags);
// otherwise every voxel a sample in b's cells can read is unallocated, unobserved or at least
// 0.999 truncation from a surface. A zero crossing there would have to jump from >= +0.999 to
// <= -0.999 truncation within one voxel, which fusion writes only across a depth discontinuity and
// which the band-only volume's garbage collection frees with the block: the surfaces such a block
// holds are none that the band-only volume keeps. The raycast treats a block not near a surface
// as unallocated (skipped whole, and left out of the ray intervals), with one exception: the first
// sample after one in a block near a surface is taken, so that a crossing between the two (the
// march's step from just in front of a surface may land past it) is bracketed as before. The
// entry into the next block is then an entry from empty space, which the march already handles:
// the sample just inside it cannot have crossed from a positive value at the border, since the
// trilinear field changes by at most two truncations per voxel and the border's value
// interpolates voxels at >= +0.999 truncation (or mixes signs: the jump above).
SEAMLESS_HD inline bool block_near_surface(const HashTableView& t, const std::int32_t* surface, int3 b,
                                           std::int32_t block) {
  if (surface[block]) return true;
  for (int k = 1; k < 8; ++k) {
    const int3 n{b.x + (k & 1), b.y + ((k >> 1) & 1), b.z + (k >> 2)};
    if (!block_in_range(n)) continue;
    const std::int32_t s = t.find_stable(pack_block(n));
    const std::int32_t i = s < 0 ? -1 : t.values[s];
    if (i >= 0 && surface[i]) return true;
  }
  return false;
}

template <Executor Exec, class Acc = HashAccess> struct TsdfRaycast {
  // Empties every tile (near = +inf, far = 0), and window w when given (every entry -1).
  static void clear_ray_intervals(const Exec& ex, RayIntervals iv, BlockWindow w = {});

  // One thread per hash slot of `slots` (the whole table by default): each live block's cell box
  // [8b, 8b+8]^3 (voxel units; every sample a ray can take in the block lies in it), clipped to the
  // depth slab [min_depth, max_depth], is projected, and the tiles under its pixel bounding box take
  // the min / max of its depth range.
  // With a window w (cleared by clear_ray_intervals) the same pass fills it, as fill_block_window
  // does: one pass over the slots instead of two. With surface flags (per pool block) the same
  // pass also sets near[block] = block_near_surface(...) and splats only the blocks near a surface.
  static void splat_ray_intervals(const Exec& ex, HashTableView t, VoxelGeometry geom, Intrinsics K, SE3 world_T_camera,
                                  float min_depth, float max_depth, RayIntervals iv, BlockWindow w = {},
                                  const std::int32_t* surface = nullptr, std::int32_t* near = nullptr,
                                  SlotRange slots = {});

  // near[block] = block_near_surface(...) for every live block (one thread per hash slot): the
  // stand-alone version of what splat_ray_intervals does with surface flags.
  static void mark_near_surface(const Exec& ex, HashTableView t, const std::int32_t* surface, std::int32_t* near);

  // Fills window w from the hash table: -1 everywhere, then the pool index of every live block
  // inside it. Run after the last change to the table and before the kernels that read through it.
  static void fill_block_window(const Exec& ex, HashTableView t, BlockWindow w);

  // One ray per pixel from min_depth to max_depth, or only over its tile's interval when iv.bits is
  // set: skips unallocated blocks whole (and blocks not near a surface, when the accessor has
  // near_surface flags), steps by the TSDF inside the others, refines the +/- zero crossing by
  // regula falsi on the trilinear field (KinectFusion section 3.5; Niessner section 4.3); a second
  // pass takes each hit's normal from its neighbours' vertices (vertex_map_normal). A ray starting
  // before its tile's near depth is in skipped blocks up to there, where the full march skips
  // block by block, so both take the same samples from the first block on and hit the same surfaces.
  static void raycast(const Exec& ex, Acc a, Intrinsics K, SE3 world_T_camera, float min_depth, float max_depth,
                      RaycastOutput out, RayIntervals iv = {});
  // An accessor derived from Acc (WindowedHashAccess from HashAccess) would be sliced into Acc and
  // silently lose what it adds (the window: a third of the raycast's time): name the family by the
  // accessor actually passed, TsdfRaycast<Exec, Derived>.
  template <class Derived, class... Rest>
  requires(!std::is_same_v<Derived, Acc> &&
           std::is_base_of_v<Acc, Derived>) static void raycast(const Exec& ex, Derived a, Rest&&... rest) = delete;
};

}  // namespace seamless::kernels

// --- extraction (family recon/tsdf_extract) ----------------------------------------------------
namespace seamless::kernels {

// Marching cubes (Lorensen & Cline 1987) over the cells of the listed blocks: cell g spans voxels
// g .. g+(1,1,1), so the cells on a block's upper faces reach into the neighbour blocks and the
// mesh has no seams. table: 256 rows of kMcRow entries, 3 edge indices per triangle, -1 ended
// (recon/marching_cubes.cpp generates it). Edge e joins corners kMcEdge[e][0] and [1]; corner k
// is g + (k&1, (k>>1)&1, k>>2).
constexpr int kMcRow = 16;
}  // namespace seamless::kernels

namespace seamless::kernels {

// Static scene particles, taken from the hash blocks of the volume, in two
// passes over the listed blocks and a thinning (tsdf_extract.inl says why): the candidates of a
// block are owned by the points of the lattice spacing * Z^3 inside it. Lattice point L gives the
// zero crossings of the TSDF on the segments L -> L + spacing e_axis (axis x, y, z) where the
// surface faces along that axis (surface particles ON the fused surface, about one per spacing^2),
// plus L itself when interior_depth > 0 and its TSDF is in [-interior_depth, -spacing/2] (the
// solid fill, as far as the truncated TSDF knows it). Candidate slots of lattice point i % m^3 of
// block i / m^3 with m = lattice_per_block(...): counts[i] = its candidates; returns the total
// and turns counts into offsets.
SEAMLESS_HD inline int lattice_per_block(float voxel_size, float spacing) {
  return static_cast<int>(ceilf(kBlockSide * voxel_size / spacing)) + 1;
}

template <Executor Exec, class Acc = HashAccess> struct TsdfExtract {
  // counts[i] = triangles of cell i (block i / 512, voxel i % 512); returns the total and turns
  // counts into exclusive offsets.
  static std::int64_t mesh_count(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                                 View<std::int32_t> counts);

  // Sorts blocks by coordinate (x, then y, then z; keys: scratch of blocks.size): meshed in that
  // order, the vertices' order follows the scene, not the hash slots, which depend on the table's
  // size and on which thread inserted a block first.
  static void sort_blocks(const Exec& ex, View<int3> blocks, View<HashKey> keys);

  // The triangles' corners, 3 a triangle at 3 * offsets[i]: the key naming the voxel edge each lies
  // on (equal keys = the same vertex) and the cell it belongs to (i).
  static void mesh_edges(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                         View<const std::int32_t> offsets, View<std::uint64_t> edge_keys, View<std::int32_t> cells);

  // Vertex j at corner corners[j] (an index into mesh_edges' output, whose cells it takes): position
  // (world), normal (TSDF gradient), colour. Computed once a vertex, for the corner that first names
  // it, rather than once for each of the ~5 triangle corners that share it.
  static void mesh_vertices(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                            View<const std::int32_t> offsets, View<const std::int32_t> cells,
                            View<const std::int32_t> corners, View<vec3> positions, View<vec3> normals,
                            View<uchar3> colors);

  // Block coordinates of the given hash slots.
  static void slot_block_coords(const Exec& ex, HashTableView t, View<const std::int32_t> slots, View<int3> out);

  // The candidates' counts of the lattice points (see lattice_per_block above).
  static std::int64_t scene_particle_count(const Exec& ex, Acc a, View<const int3> blocks, float spacing,
                                           float interior_depth, View<std::int32_t> counts);

  // Writes each candidate's position, unit normal (TSDF gradient) and thinning score at offsets[i].
  static void scene_particle_emit(const Exec& ex, Acc a, View<const int3> blocks, float spacing, float interior_depth,
                                  View<const std::int32_t> offsets, View<vec3> positions, View<vec3> normals,
                                  View<float> scores);

  // keep[i] = 0 for a candidate within min_distance of one that outranks it (higher score first),
  // else 1; keys and order are scratch (one per candidate). Returns how many are kept and turns keep
  // into offsets for scene_particle_compact, which copies the kept ones to out (kept of them).
  static std::int64_t scene_particle_thin(const Exec& ex, View<const vec3> positions, View<const float> scores,
                                          float min_distance, View<std::uint64_t> keys, View<std::int32_t> order,
                                          View<std::int32_t> keep);

  static void scene_particle_compact(const Exec& ex, View<const std::int32_t> offsets, std::int64_t kept,
                                     View<const vec3> positions, View<const vec3> normals, View<vec3> out_positions,
                                     View<vec3> out_normals);

  // Samples the SDF (sample_sdf) on a regular grid, x fastest: out[(z * dims.y + y) * dims.x + x] at
  // origin + voxel * (x, y, z). Unknown points (unobserved or outside the band) get `unknown`.
  // For collisions against the TSDF through a dense grid (the solver's scene_collision: sdf).
  static void sample_sdf_grid(const Exec& ex, Acc a, vec3 origin, int3 dims, float voxel, float unknown,
                              View<float> out);
};

}  // namespace seamless::kernels
