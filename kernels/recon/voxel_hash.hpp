// Voxel hashing after Niessner, Zollhoefer, Izadi, Stamminger 2013 ("Real-time 3D Reconstruction at
// Scale using Voxel Hashing"): the scene is a sparse set of 8^3-voxel blocks; a hash table maps
// integer block coordinates to an index into a pool of blocks. Everything here is per-element and
// SEAMLESS_HD so that any kernel (fusion, raycast, marching cubes, the physics solver's SDF
// collisions) can look voxels up on either backend.
//
// Table design (see docs/RECONSTRUCTION.md): open addressing with linear probing over a
// power-of-two array of 64-bit keys plus a parallel array of block indices. A slot's key only ever
// moves empty -> key -> tombstone, and insertion never reuses tombstones, so concurrent inserts of
// the same key cannot create duplicates: two threads inserting k walk the same probe sequence and
// meet at the first slot that was empty, where exactly one compare-and-swap wins. Tombstones are
// cleared by a rehash between frames.
#pragma once
#include <cstdint>

#include "core/atomics.hpp"
#include "core/math.hpp"

namespace seamless::kernels {

constexpr int kBlockSide = 8;
constexpr int kBlockVoxels = kBlockSide * kBlockSide * kBlockSide;

// 4 bytes: the TSDF and the fusion weight as 16-bit integers (the distance as InfiniTAM stores
// it, Kaehler et al. 2015, whose weight is a byte): what every stage reads, so the march and fusion, which are bound by
// voxel loads, move half the bytes of two floats, and a cache line holds two of a block's rows along x, so a cell with
// even y finds its 8 corners in 2 lines instead of 4. A voxel's fused colour is kept in a pool of its own with the same
// index (the accessors' `colors`), read only by the stages that use colour.
//
// Distance: the TSDF divided by the truncation mu as snorm16, round(32767 sdf / mu). Fusion
// truncates every observation to [-mu, mu] and the running average of such values stays inside,
// so the full 16 bits cover exactly the range that occurs, uniformly: a step of mu / 32767 (0.6 um
// at mu = 2 cm), far below an RGB-D camera's depth noise (millimetres). IEEE half
// instead would be finer near zero but coarser near mu (15 um at 2 cm), and its conversion is a
// libm sequence on an x86-64 host without F16C, where snorm16 is an integer conversion and a
// multiply on both backends. Decoding needs mu, which every reader has (VoxelGeometry).
//
// Weight: a whole count of fused frames, 0 = never observed, capped at volume.max_weight, which is
// therefore limited to a whole number up to kMaxVoxelWeight (volume_params.hpp checks it). Every
// write is +1 (or a reset to 1 or 0), so the count is exact, where a 16-bit float would stall at
// 2048.
//
// The running average in steps is q <- q + (t - q) / (w + 1), rounded to nearest (fuse_tsdf): a
// change survives the rounding when it is at least half a step, i.e. when the observation t lies
// (w + 1) / 2 steps or more from the stored q. With the default cap of 100 a constant input is
// reached to within 51 steps (31 um at mu = 2 cm) and every larger disagreement still moves the
// value; truncation instead of rounding would stop a whole (w + 1) steps short, and always on
// the same side.
struct Voxel {
  std::int16_t sdf16;      // round(32767 * TSDF / truncation), in [-32767, 32767]
  std::uint16_t weight16;  // fused frames, at most the weight cap
};
constexpr float kSdfSteps = 32767.f;  // snorm16 steps per truncation
constexpr int kMaxVoxelWeight = 65535;

// TSDF of v in metres (mu: the truncation).
SEAMLESS_HD inline float voxel_sdf(const Voxel& v, float mu) { return static_cast<float>(v.sdf16) * (mu / kSdfSteps); }
SEAMLESS_HD inline float voxel_weight(const Voxel& v) { return static_cast<float>(v.weight16); }
SEAMLESS_HD inline bool voxel_observed(const Voxel& v) { return v.weight16 != 0; }
// Nearest step of a TSDF given in steps (sdf / mu * kSdfSteps), clamped to the truncation; ties
// away from zero. The truncating conversion of steps +- 1/2 is one instruction on either backend.
SEAMLESS_HD inline std::int16_t sdf_steps(float steps) {
  steps = steps >= -kSdfSteps ? (steps <= kSdfSteps ? steps : kSdfSteps) : -kSdfSteps;
  return static_cast<std::int16_t>(static_cast<int>(steps + copysignf(0.5f, steps)));
}
// The voxel holding sdf (metres, truncation mu) with weight (a whole count up to kMaxVoxelWeight).
SEAMLESS_HD inline Voxel make_voxel(float sdf, float mu, float weight) {
  return {sdf_steps(sdf * (kSdfSteps / mu)), static_cast<std::uint16_t>(weight)};
}
// One frame's observation tsdf (metres, in [-mu, mu]) into the running average (Curless & Levoy
// 1996; KinectFusion eq. 11-12), the weight capped at max_weight (a whole count, see Voxel). The
// scale kSdfSteps / mu is the same for every voxel (a caller's loop computes it once): a multiply,
// not a second division next to the one by w + 1.
SEAMLESS_HD inline void fuse_tsdf(Voxel& v, float tsdf, float mu, float max_weight) {
  const float w = voxel_weight(v), q = static_cast<float>(v.sdf16);
  v.sdf16 = sdf_steps(q + (tsdf * (kSdfSteps / mu) - q) / (w + 1.f));
  v.weight16 = static_cast<std::uint16_t>(min_of(w + 1.f, max_weight));
}

using HashKey = unsigned long long;  // the type CUDA's 64-bit atomicCAS takes
constexpr HashKey kEmptyKey = ~0ull;
constexpr HashKey kTombstone = ~0ull - 1ull;
// 21 bits per block coordinate, biased: +-2^20 blocks (+-42 km at 5 mm voxels). Packed keys use
// 63 bits, so the two sentinels (top bit set) can never be a block's key.
constexpr int kCoordBits = 21;
constexpr int kCoordBias = 1 << (kCoordBits - 1);

SEAMLESS_HD inline bool block_in_range(int3 b) {
  return b.x >= -kCoordBias && b.x < kCoordBias && b.y >= -kCoordBias && b.y < kCoordBias && b.z >= -kCoordBias &&
         b.z < kCoordBias;
}
SEAMLESS_HD inline HashKey pack_block(int3 b) {
  const HashKey m = (1ull << kCoordBits) - 1ull;
  return ((static_cast<HashKey>(b.x + kCoordBias) & m) << (2 * kCoordBits)) |
         ((static_cast<HashKey>(b.y + kCoordBias) & m) << kCoordBits) | (static_cast<HashKey>(b.z + kCoordBias) & m);
}
SEAMLESS_HD inline int3 unpack_block(HashKey k) {
  const HashKey m = (1ull << kCoordBits) - 1ull;
  return {static_cast<int>((k >> (2 * kCoordBits)) & m) - kCoordBias,
          static_cast<int>((k >> kCoordBits) & m) - kCoordBias, static_cast<int>(k & m) - kCoordBias};
}
SEAMLESS_HD inline bool is_live_key(HashKey k) { return k != kEmptyKey && k != kTombstone; }

// MurmurHash3's 64-bit finaliser: linear probing needs neighbouring blocks spread apart, which
// Niessner's xor of coordinate-times-prime does not guarantee for small coordinates.
SEAMLESS_HD inline std::uint64_t mix64(std::uint64_t k) {
  k ^= k >> 33;
  k *= 0xff51afd7ed558ccdull;
  k ^= k >> 33;
  k *= 0xc4ceb9fe1a85ec53ull;
  k ^= k >> 33;
  return k;
}

enum class InsertResult : int { Found = 0, Inserted = 1, Full = 2 };

// Per-table counters that live on the device; the host reads the struct once per frame.
struct HashCounters {
  int free_top;        // blocks on the free list (may dip below 0 during a failed allocation pass)
  int tombstones;      // deleted slots not yet reclaimed by a rehash
  int inserted;        // keys inserted this frame
  int collisions;      // inserted keys that did not land in their home slot
  int probe_failures;  // insertions that found no empty slot within max_probe
  int pool_failures;   // insertions that found no free block in the pool
  int visible;         // blocks in the visible list
  int removed;         // blocks freed by garbage collection
  int listed;          // live slots listed this frame (TsdfFusion::find_visible_blocks)
};

struct HashTableView {
  HashKey* keys = nullptr;
  std::int32_t* values = nullptr;  // block index in the pool; -1: none (yet); -2: being assigned
  std::uint32_t mask = 0;          // slots - 1 (slots is a power of two)
  int max_probe = 64;

  SEAMLESS_HD std::uint32_t home(HashKey k) const { return static_cast<std::uint32_t>(mix64(k)) & mask; }

  // Slot holding key, or -1. Safe concurrently with insert and erase of other keys.
  SEAMLESS_HD std::int32_t find(HashKey key) const { return probe<true>(key); }
  // The same for kernels during which nobody modifies the table (raycast, extraction, the physics
  // SDF sampler): plain loads, which the GPU caches in L1, where atomic (volatile) loads go to L2
  // on every probe.
  SEAMLESS_HD std::int32_t find_stable(HashKey key) const { return probe<false>(key); }

  // Claims a slot for key (or finds the one that holds it). *probes is how far from home it is.
  SEAMLESS_HD InsertResult insert(HashKey key, std::int32_t* slot, int* probes) const {
    std::uint32_t s = home(key);
    for (int p = 0; p < max_probe; ++p, s = (s + 1) & mask) {
      HashKey k = atomic_load(&keys[s]);
      if (k == kEmptyKey) k = atomic_cas(&keys[s], kEmptyKey, key);
      if (k == kEmptyKey || k == key) {
        *slot = static_cast<std::int32_t>(s);
        *probes = p;
        return k == kEmptyKey ? InsertResult::Inserted : InsertResult::Found;
      }
    }
    return InsertResult::Full;
  }

  template <bool Atomic> SEAMLESS_HD std::int32_t probe(HashKey key) const {
    std::uint32_t s = home(key);
    for (int p = 0; p < max_probe; ++p, s = (s + 1) & mask) {
      HashKey k = Atomic ? atomic_load(&keys[s]) : keys[s];
      if (k == key) return static_cast<std::int32_t>(s);
      if (k == kEmptyKey) return -1;
    }
    return -1;
  }

  // Turns key's slot into a tombstone; returns the slot it held, or -1 if absent.
  SEAMLESS_HD std::int32_t erase(HashKey key) const {
    std::int32_t s = find(key);
    if (s < 0) return -1;
    return atomic_cas(&keys[s], key, kTombstone) == key ? s : -1;
  }
};

// Pops a free block index (-1 when the pool is exhausted). Pops and pushes never share a kernel.
SEAMLESS_HD inline std::int32_t pool_pop(HashCounters* c, const std::int32_t* free_list) {
  int top = atomic_add(&c->free_top, -1);
  return top > 0 ? free_list[top - 1] : -1;
}
SEAMLESS_HD inline void pool_push(HashCounters* c, std::int32_t* free_list, std::int32_t block) {
  int pos = atomic_add(&c->free_top, 1);
  free_list[pos] = block;
}

// --- Voxel access shared by the hash volume and the dense grid --------------------------------
// A "block access" maps a block coordinate to a block index in a pool of 8^3-voxel blocks stored
// block-major (voxel (x,y,z) of block i at voxels[i*512 + x + 8y + 64z]). Voxel g (integer voxel
// coordinates) sits at world position origin + g * voxel_size.

struct VoxelGeometry {
  vec3 origin{0.f, 0.f, 0.f};
  float voxel_size = 0.005f;
  float truncation = 0.02f;
  SEAMLESS_HD vec3 to_voxel(vec3 p) const { return (p - origin) / voxel_size; }
  SEAMLESS_HD vec3 to_world(vec3 g) const { return origin + g * voxel_size; }
};

SEAMLESS_HD inline int3 block_of_voxel(int3 g) { return {g.x >> 3, g.y >> 3, g.z >> 3}; }  // floor division
SEAMLESS_HD inline int local_index(int3 g) { return (g.x & 7) + 8 * (g.y & 7) + 64 * (g.z & 7); }
SEAMLESS_HD inline int3 local_coords(int i) { return {i & 7, (i >> 3) & 7, i >> 6}; }

// Voxel hashing access: the device view of a VoxelHashVolume that physics kernels may copy. Only
// for kernels that run between frames (no concurrent insertion or removal): lookups use plain loads.
struct HashAccess {
  HashTableView table;
  Voxel* voxels = nullptr;
  uchar3* colors = nullptr;  // colour of voxels[i] at colors[i]
  VoxelGeometry geom;
  // Per pool block, for the raycast only: 0 where the block is not near a surface
  // (block_near_surface in tsdf.hpp), which the march then skips like an unallocated block.
  // nullptr (every other user): no block is skipped.
  const std::int32_t* near_surface = nullptr;
  SEAMLESS_HD std::int32_t find_block(int3 b) const {
    if (!block_in_range(b)) return -1;
    std::int32_t s = table.find_stable(pack_block(b));
    return s < 0 ? -1 : table.values[s];
  }
};

// A dense window of block indices (side^3 entries, x fastest, -1 = no block) over part of the
// block grid, filled from the hash table before a raycast (fill_block_window): inside it a block is
// found with one load instead of a chain of hash probes, and an empty block, which open addressing
// can only confirm by probing up to an empty slot, costs no more than a full one. Rays cross 10-20
// blocks each (most of them empty space skipped block by block), so that chain was most of the
// raycast's latency. The window is a cache: outside it the table answers, so results are equal.
struct BlockWindow {
  std::int32_t* index = nullptr;  // nullptr: no window
  int3 origin{0, 0, 0};           // block coordinate of entry 0
  int side = 0;
  SEAMLESS_HD std::int64_t count() const { return static_cast<std::int64_t>(side) * side * side; }
  // Entry of block b, or -1 when b is outside (unsigned compares catch negatives too).
  SEAMLESS_HD std::int64_t entry(int3 b) const {
    const unsigned x = static_cast<unsigned>(b.x - origin.x), y = static_cast<unsigned>(b.y - origin.y),
                   z = static_cast<unsigned>(b.z - origin.z), n = static_cast<unsigned>(side);
    if (x >= n || y >= n || z >= n) return -1;
    return x + static_cast<std::int64_t>(n) * (y + static_cast<std::int64_t>(n) * z);
  }
};

// HashAccess with a BlockWindow in front of the table (same answers, fewer probes).
struct WindowedHashAccess : HashAccess {
  BlockWindow window;
  SEAMLESS_HD std::int32_t find_block(int3 b) const {
    const std::int64_t e = window.index ? window.entry(b) : -1;
    return e >= 0 ? window.index[e] : HashAccess::find_block(b);
  }
  // The blocks of a cell's 8 corners (see cell_voxels) straight from the window, without the
  // block cache's bookkeeping: block b0 + (k&1 & ex, (k>>1)&1 & ey, k>>2 & ez) for corner k.
  // False when the cell's far block is outside the window (the caller then uses find_block).
  SEAMLESS_HD bool corner_blocks(int3 b0, bool ex, bool ey, bool ez, std::int32_t i[8]) const {
    const std::int64_t e0 = window.index ? window.entry(b0) : -1;
    if (e0 < 0 || window.entry(b0 + int3{ex, ey, ez}) < 0) return false;
    const std::int64_t n = window.side, dx = ex, dy = ey ? n : 0, dz = ez ? n * n : 0;
    for (int k = 0; k < 8; ++k) i[k] = window.index[e0 + (k & 1 ? dx : 0) + (k & 2 ? dy : 0) + (k & 4 ? dz : 0)];
    return true;
  }
};

// Dense grid access: blocks_per_side^3 blocks starting at block (0,0,0); the dense KinectFusion
// volume stored brick-major so that every kernel below serves both layouts.
struct DenseAccess {
  Voxel* voxels = nullptr;
  uchar3* colors = nullptr;  // colour of voxels[i] at colors[i]
  int blocks_per_side = 0;
  VoxelGeometry geom;
  SEAMLESS_HD std::int32_t find_block(int3 b) const {
    int n = blocks_per_side;
    if (b.x < 0 || b.y < 0 || b.z < 0 || b.x >= n || b.y >= n || b.z >= n) return -1;
    return b.x + n * (b.y + n * b.z);
  }
};

// Remembers the last two blocks looked up (most recent first): neighbouring samples mostly fall
// in the same block, and a cell on a block face reads two blocks, which one entry would look up
// in turn for every corner.
struct BlockCache {
  int3 block{-2147483647, 0, 0};
  std::int32_t index = -1;
  int3 block2{-2147483647, 0, 0};
  std::int32_t index2 = -1;
};

// Block index of b (-1: none) through the cache.
template <class Acc> SEAMLESS_HD inline std::int32_t cached_block(const Acc& a, int3 b, BlockCache& c) {
  // A window lookup is one cached load: cheaper than the cache's compares and shuffling.
  if constexpr (requires { a.window; }) return a.find_block(b);
  if (b == c.block) return c.index;
  const int3 old_block = c.block;
  const std::int32_t old_index = c.index;
  c.block = b;
  c.index = b == c.block2 ? c.index2 : a.find_block(b);
  c.block2 = old_block, c.index2 = old_index;
  return c.index;
}

template <class Acc> SEAMLESS_HD inline const Voxel* find_voxel(const Acc& a, int3 g, BlockCache& c) {
  std::int32_t index = cached_block(a, block_of_voxel(g), c);
  return index < 0 ? nullptr : a.voxels + static_cast<std::int64_t>(index) * kBlockVoxels + local_index(g);
}

// v[k] = corner k of cell g0, in block i[k]; false when a corner's block is missing.
template <class Acc>
SEAMLESS_HD inline bool corner_voxels(const Acc& a, int3 g0, const std::int32_t i[8], const Voxel* v[8]) {
  for (int k = 0; k < 8; ++k) {
    if (i[k] < 0) return false;
    int3 g = g0 + int3{k & 1, (k >> 1) & 1, k >> 2};
    v[k] = a.voxels + static_cast<std::int64_t>(i[k]) * kBlockVoxels + local_index(g);
  }
  return true;
}

// The 8 corner voxels of cell g0 (corner k at g0 + (k&1, (k>>1)&1, k>>2)), each block looked up
// once: the cell reaches into the next block only along the axes where g0 is a block's last
// voxel. False when a corner's block is missing.
template <class Acc> SEAMLESS_HD inline bool cell_voxels(const Acc& a, int3 g0, BlockCache& c, const Voxel* v[8]) {
  const int3 b0 = block_of_voxel(g0);
  const bool ex = (g0.x & 7) == 7, ey = (g0.y & 7) == 7, ez = (g0.z & 7) == 7;
  if (!(ex || ey || ez)) {  // 343 of a block's 512 cells: all corners in b0, at fixed offsets
    const std::int32_t i0 = cached_block(a, b0, c);
    if (i0 < 0) return false;
    const Voxel* base = a.voxels + static_cast<std::int64_t>(i0) * kBlockVoxels + local_index(g0);
    for (int k = 0; k < 8; ++k) v[k] = base + (k & 1) + 8 * ((k >> 1) & 1) + 64 * (k >> 2);
    return true;
  }
  // i[k]: block of corner k, i.e. of b0 + (k&1 & ex, (k>>1)&1 & ey, k>>2 & ez).
  std::int32_t i[8];
  if constexpr (requires { a.corner_blocks(b0, ex, ey, ez, i); }) {
    if (a.corner_blocks(b0, ex, ey, ez, i)) return corner_voxels(a, g0, i, v);
  }
  i[0] = cached_block(a, b0, c);
  i[1] = ex ? cached_block(a, b0 + int3{1, 0, 0}, c) : i[0];
  i[2] = ey ? cached_block(a, b0 + int3{0, 1, 0}, c) : i[0];
  i[3] = ex && ey ? cached_block(a, b0 + int3{1, 1, 0}, c) : ex ? i[1] : i[2];
  i[4] = ez ? cached_block(a, b0 + int3{0, 0, 1}, c) : i[0];
  i[5] = ex && ez ? cached_block(a, b0 + int3{1, 0, 1}, c) : ex ? i[1] : i[4];
  i[6] = ey && ez ? cached_block(a, b0 + int3{0, 1, 1}, c) : ey ? i[2] : i[4];
  i[7] = ex && ey && ez ? cached_block(a, b0 + int3{1, 1, 1}, c) : !ex ? i[6] : !ey ? i[5] : i[3];
  return corner_voxels(a, g0, i, v);
}

// sample_tsdf with the cell's first voxel g0 = floor(q) and the index i0 (>= 0) of its block
// already known (the raycast looks the block up to skip empty space anyway). A cell inside its
// block (343 of 512) reads its corners at fixed offsets from one pointer here, inline: through
// cell_voxels' array of pointers (a call the compiler keeps out of line) the CPU raycast spent a
// third of its instructions on that bookkeeping. The values and the arithmetic are sample_tsdf's.
template <class Acc>
SEAMLESS_HD inline bool sample_tsdf_in(const Acc& a, vec3 q, int3 g0, std::int32_t i0, BlockCache& c, float* sdf,
                                       vec3* color = nullptr) {
#ifndef __CUDA_ARCH__
  // On the CPU, corner 0 first: its block is known, and an unobserved corner means no value (a
  // sixth of the raycast's samples end here, at the edge of what was seen) without the other
  // seven. Not on the GPU, where the other seven loads would wait for this one's latency.
  if (!voxel_observed(a.voxels[static_cast<std::int64_t>(i0) * kBlockVoxels + local_index(g0)])) return false;
#endif
  const vec3 f = q - to_vec3(g0);
  const Voxel* v[8];
  if ((g0.x & 7) != 7 && (g0.y & 7) != 7 && (g0.z & 7) != 7) {
    const Voxel* base = a.voxels + static_cast<std::int64_t>(i0) * kBlockVoxels + local_index(g0);
    for (int k = 0; k < 8; ++k) v[k] = base + (k & 1) + 8 * ((k >> 1) & 1) + 64 * (k >> 2);
  } else if (!cell_voxels(a, g0, c, v)) {
    return false;
  }
  float d[8];  // in snorm16 steps (Voxel), scaled to metres once after the interpolation
  bool observed = true;
  for (int k = 0; k < 8; ++k) observed &= voxel_observed(*v[k]), d[k] = static_cast<float>(v[k]->sdf16);
  if (!observed) return false;
  // Trilinear as 7 lerps along x, then y, then z (the same weights as the 8-product form).
  auto lerp = [](float p, float q, float t) { return p + t * (q - p); };
  const float x0 = lerp(d[0], d[1], f.x), x1 = lerp(d[2], d[3], f.x), x2 = lerp(d[4], d[5], f.x),
              x3 = lerp(d[6], d[7], f.x);
  *sdf = lerp(lerp(x0, x1, f.y), lerp(x2, x3, f.y), f.z) * (a.geom.truncation / kSdfSteps);
  if (!color) return true;
  vec3 col{0.f, 0.f, 0.f};
  for (int k = 0; k < 8; ++k) {
    const float w = (k & 1 ? f.x : 1.f - f.x) * ((k >> 1) & 1 ? f.y : 1.f - f.y) * (k >> 2 ? f.z : 1.f - f.z);
    const uchar3 ck = a.colors[v[k] - a.voxels];
    col += vec3{float(ck.x), float(ck.y), float(ck.z)} * w;
  }
  *color = col;
  return true;
}

// Trilinear interpolation of the TSDF (metres) and colour at voxel-space point q. False when any of
// the 8 corners is unallocated or unobserved (weight 0): no value is invented there.
template <class Acc>
SEAMLESS_HD inline bool sample_tsdf(const Acc& a, vec3 q, BlockCache& c, float* sdf, vec3* color = nullptr) {
  const int3 g0 = floor_to_int(q);
  const std::int32_t i0 = cached_block(a, block_of_voxel(g0), c);
  return i0 >= 0 && sample_tsdf_in(a, q, g0, i0, c, sdf, color);
}

// Gradient of the trilinear TSDF at voxel-space q (metres of SDF per voxel) by central differences
// over +-1 voxel, one-sided (against the value s0 at q) where a neighbour sample is missing.
template <class Acc>
SEAMLESS_HD inline vec3 tsdf_gradient(const Acc& a, vec3 q, float s0, BlockCache& c, bool* complete = nullptr) {
  float g[3];
  if (complete) *complete = true;
  for (int axis = 0; axis < 3; ++axis) {
    vec3 e{axis == 0 ? 1.f : 0.f, axis == 1 ? 1.f : 0.f, axis == 2 ? 1.f : 0.f};
    float sp = 0.f, sm = 0.f;
    bool okp = sample_tsdf(a, q + e, c, &sp), okm = sample_tsdf(a, q - e, c, &sm);
    if (complete && !(okp && okm)) *complete = false;
    g[axis] = okp && okm ? 0.5f * (sp - sm) : okp ? sp - s0 : okm ? s0 - sm : 0.f;
  }
  return {g[0], g[1], g[2]};
}

// SDF value (metres) and gradient (unit-free, ~unit length near the surface) at world point p, for
// collisions against the fused scene (the smoother alternative of the dissertation's section
// 2.6.4). False where the TSDF is unknown (unallocated or unobserved).
template <class Acc> SEAMLESS_HD inline bool sample_sdf(const Acc& a, vec3 p, float* value, vec3* gradient) {
  BlockCache c;
  vec3 q = a.geom.to_voxel(p);
  float s0;
  if (!sample_tsdf(a, q, c, &s0)) return false;
  *value = s0;
  if (gradient) *gradient = tsdf_gradient(a, q, s0, c) / a.geom.voxel_size;
  return true;
}

}  // namespace seamless::kernels
