// Kernel bodies for extraction in recon/tsdf.hpp (marching cubes, scene particles), compiled once
// per backend.
#include <cmath>

#include "kernels/recon/tsdf.hpp"

namespace seamless::kernels {

SEAMLESS_HD inline int3 mc_corner(int k) { return {k & 1, (k >> 1) & 1, k >> 2}; }
// Edge e: axis e/4; its lower corner has the other two bits from e%4.
SEAMLESS_HD inline void mc_edge(int e, int* c0, int* c1) {
  int axis = e / 4, j = e % 4;
  int bit = 1 << axis;
  int lo = 0, m = 0;
  for (int b = 0; b < 3; ++b) {
    if (b == axis) continue;
    if (j & (1 << m)) lo |= 1 << b;
    ++m;
  }
  *c0 = lo;
  *c1 = lo | bit;
}

// The cube at cell g: its 8 corner voxels, or -1 when one is missing or unobserved, or when the
// sign change is between truncated values (the +mu / -mu seam behind a surface, not a surface).
template <class Acc>
SEAMLESS_HD inline int mc_cube(const Acc& a, int3 g, BlockCache& c, const Voxel* v[8]) {
  int cube = 0;
  bool truncated = false;
  const float trunc = 0.999f * a.geom.truncation;
  if (!cell_voxels(a, g, c, v)) return -1;
  for (int k = 0; k < 8; ++k) {
    if (!(v[k]->weight > 0.f)) return -1;
    if (v[k]->sdf < 0.f) cube |= 1 << k;
    if (fabsf(v[k]->sdf) >= trunc) truncated = true;
  }
  if (cube == 0 || cube == 255) return 0;
  return truncated ? -1 : cube;
}

// Gradient of the trilinear interpolant of one cell's corners at local position f in [0,1]^3:
// the normal where the wider central difference has a missing neighbour (edges of the model).
SEAMLESS_HD inline vec3 cell_gradient(const Voxel* const v[8], vec3 f) {
  vec3 g{0.f, 0.f, 0.f};
  for (int k = 0; k < 8; ++k) {
    int3 o = mc_corner(k);
    float wx = o.x ? f.x : 1.f - f.x, wy = o.y ? f.y : 1.f - f.y, wz = o.z ? f.z : 1.f - f.z;
    float sx = o.x ? 1.f : -1.f, sy = o.y ? 1.f : -1.f, sz = o.z ? 1.f : -1.f;
    g += vec3{sx * wy * wz, sy * wx * wz, sz * wx * wy} * v[k]->sdf;
  }
  return g;
}

SEAMLESS_HD inline int3 cell_of(View<const int3> blocks, std::int64_t i) {
  int3 b = blocks[i / kBlockVoxels], l = local_coords(static_cast<int>(i % kBlockVoxels));
  return {b.x * 8 + l.x, b.y * 8 + l.y, b.z * 8 + l.z};
}

template <class Exec, class Acc>
std::int64_t mesh_count(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                        View<std::int32_t> counts) {
  const std::int64_t n = blocks.size * kBlockVoxels;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    BlockCache c;
    const Voxel* v[8];
    int cube = mc_cube(a, cell_of(blocks, i), c, v);
    int tris = 0;
    if (cube > 0)
      while (tris * 3 < kMcRow && table[cube * kMcRow + tris * 3] >= 0) ++tris;
    counts[i] = tris;
  });
  return ex.exclusive_scan(counts.data, counts.data, n);
}

// Packs a voxel edge (lower corner g, axis) into 64 bits: 20 bits a coordinate, 2 for the axis.
SEAMLESS_HD inline std::uint64_t edge_key(int3 g, int axis) {
  const std::uint64_t m = (1ull << 20) - 1ull, bias = 1ull << 19;
  return (((std::uint64_t(g.x) + bias) & m) << 42) | (((std::uint64_t(g.y) + bias) & m) << 22) |
         (((std::uint64_t(g.z) + bias) & m) << 2) | std::uint64_t(axis);
}

template <class Exec, class Acc>
void mesh_emit(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
               View<const std::int32_t> offsets, View<vec3> positions, View<vec3> normals, View<uchar3> colors,
               View<std::uint64_t> edge_keys) {
  const std::int64_t n = blocks.size * kBlockVoxels;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    BlockCache c;
    const Voxel* v[8];
    int3 g = cell_of(blocks, i);
    int cube = mc_cube(a, g, c, v);
    if (cube <= 0) return;
    std::int64_t out = 3ll * offsets[i];
    for (int k = 0; k < kMcRow && table[cube * kMcRow + k] >= 0; ++k, ++out) {
      int e = table[cube * kMcRow + k], c0, c1;
      mc_edge(e, &c0, &c1);
      float f0 = v[c0]->sdf, f1 = v[c1]->sdf;
      float t = f0 / (f0 - f1);  // linear interpolation of the zero crossing along the edge
      vec3 q = to_vec3(g + mc_corner(c0)) * (1.f - t) + to_vec3(g + mc_corner(c1)) * t;
      positions[out] = a.geom.to_world(q);
      bool complete = false;
      vec3 n = normalize(tsdf_gradient(a, q, 0.f, c, &complete));
      if (!complete) n = normalize(cell_gradient(v, q - to_vec3(g)));
      normals[out] = n;
      uchar3 k0 = v[c0]->color, k1 = v[c1]->color;
      colors[out] = {static_cast<std::uint8_t>(k0.x * (1.f - t) + k1.x * t + 0.5f),
                     static_cast<std::uint8_t>(k0.y * (1.f - t) + k1.y * t + 0.5f),
                     static_cast<std::uint8_t>(k0.z * (1.f - t) + k1.z * t + 0.5f)};
      edge_keys[out] = edge_key(g + mc_corner(c0), e / 4);
    }
  });
}

// Lattice point of candidate i, or false when it falls outside its block (blocks own the lattice
// points p with floor((p - origin) / (8 s)) == b; the same float expression decides for both
// neighbours, so no point is taken twice or lost at a seam).
template <class Acc>
SEAMLESS_HD inline bool lattice_point(const Acc& a, View<const int3> blocks, float spacing, std::int64_t i, vec3* p) {
  const int m = lattice_per_block(a.geom.voxel_size, spacing);
  const std::int64_t m3 = static_cast<std::int64_t>(m) * m * m;
  int3 b = blocks[i / m3];
  int j = static_cast<int>(i % m3);
  int l[3] = {j % m, (j / m) % m, j / (m * m)}, bb[3] = {b.x, b.y, b.z};
  float o[3] = {a.geom.origin.x, a.geom.origin.y, a.geom.origin.z}, r[3];
  const float block = kBlockSide * a.geom.voxel_size;
  for (int k = 0; k < 3; ++k) {
    float lo = o[k] + bb[k] * block, hi = lo + block;
    int first = static_cast<int>(ceilf(lo / spacing)), end = static_cast<int>(ceilf(hi / spacing));
    if (first + l[k] >= end) return false;
    r[k] = (first + l[k]) * spacing;
  }
  *p = {r[0], r[1], r[2]};
  return true;
}

template <class Acc>
SEAMLESS_HD inline bool is_scene_particle(const Acc& a, vec3 p, float spacing, float interior_depth, float* sdf) {
  BlockCache c;
  if (!sample_tsdf(a, a.geom.to_voxel(p), c, sdf)) return false;
  return *sdf <= 0.5f * spacing && *sdf >= -fmaxf(interior_depth, 0.5f * spacing);
}

template <class Exec, class Acc>
std::int64_t scene_particle_count(const Exec& ex, Acc a, View<const int3> blocks, float spacing, float interior_depth,
                                  View<std::int32_t> flags) {
  const std::int64_t n = flags.size;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    vec3 p;
    float s;
    flags[i] = lattice_point(a, blocks, spacing, i, &p) && is_scene_particle(a, p, spacing, interior_depth, &s);
  });
  return ex.exclusive_scan(flags.data, flags.data, n);
}

template <class Exec, class Acc>
void scene_particle_emit(const Exec& ex, Acc a, View<const int3> blocks, float spacing, float interior_depth,
                         View<const std::int32_t> offsets, View<vec3> positions, View<vec3> normals) {
  ex.for_each(offsets.size, [=] SEAMLESS_HD(std::int64_t i) {
    vec3 p;
    float s;
    if (!lattice_point(a, blocks, spacing, i, &p) || !is_scene_particle(a, p, spacing, interior_depth, &s)) return;
    vec3 g{0.f, 0.f, 0.f};
    sample_sdf(a, p, &s, &g);
    positions[offsets[i]] = p;
    normals[offsets[i]] = normalize(g);
  });
}

template <class Exec, class Acc>
void sample_sdf_grid(const Exec& ex, Acc a, vec3 origin, int3 dims, float voxel, float unknown, View<float> out) {
  ex.for_each(out.size, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t plane = static_cast<std::int64_t>(dims.x) * dims.y;
    int z = static_cast<int>(i / plane), y = static_cast<int>((i % plane) / dims.x), x = static_cast<int>(i % dims.x);
    vec3 p = origin + vec3{float(x), float(y), float(z)} * voxel;
    float v;
    out[i] = sample_sdf(a, p, &v, nullptr) ? v : unknown;
  });
}

template <class Exec>
void slot_block_coords(const Exec& ex, HashTableView t, View<const std::int32_t> slots, View<int3> out) {
  ex.for_each(slots.size, [=] SEAMLESS_HD(std::int64_t i) { out[i] = unpack_block(t.keys[slots[i]]); });
}

}  // namespace seamless::kernels

#define SEAMLESS_INSTANTIATE_TSDF_EXTRACT_ACC(EXEC, ACC)                                                          \
  namespace seamless::kernels {                                                                                   \
  template std::int64_t mesh_count<EXEC, ACC>(const EXEC&, ACC, View<const int3>, const std::int8_t*,             \
                                              View<std::int32_t>);                                                \
  template void mesh_emit<EXEC, ACC>(const EXEC&, ACC, View<const int3>, const std::int8_t*,                      \
                                     View<const std::int32_t>, View<vec3>, View<vec3>, View<uchar3>,              \
                                     View<std::uint64_t>);                                                        \
  template std::int64_t scene_particle_count<EXEC, ACC>(const EXEC&, ACC, View<const int3>, float, float,         \
                                                        View<std::int32_t>);                                      \
  template void scene_particle_emit<EXEC, ACC>(const EXEC&, ACC, View<const int3>, float, float,                  \
                                               View<const std::int32_t>, View<vec3>, View<vec3>);                 \
  template void sample_sdf_grid<EXEC, ACC>(const EXEC&, ACC, vec3, int3, float, float, View<float>);              \
  }
#define SEAMLESS_INSTANTIATE_TSDF_EXTRACT(EXEC)                                                                   \
  SEAMLESS_INSTANTIATE_TSDF_EXTRACT_ACC(EXEC, HashAccess)                                                         \
  SEAMLESS_INSTANTIATE_TSDF_EXTRACT_ACC(EXEC, DenseAccess)                                                        \
  namespace seamless::kernels {                                                                                   \
  template void slot_block_coords<EXEC>(const EXEC&, HashTableView, View<const std::int32_t>, View<int3>);        \
  }
