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
template <class Acc> SEAMLESS_HD inline int mc_cube(const Acc& a, int3 g, BlockCache& c, const Voxel* v[8]) {
  int cube = 0;
  bool truncated = false;
  const float trunc = 0.999f * a.geom.truncation;
  if (!cell_voxels(a, g, c, v)) return -1;
  for (int k = 0; k < 8; ++k) {
    if (!voxel_observed(*v[k])) return -1;
    const float s = voxel_sdf(*v[k], a.geom.truncation);
    if (s < 0.f) cube |= 1 << k;
    if (fabsf(s) >= trunc) truncated = true;
  }
  if (cube == 0 || cube == 255) return 0;
  return truncated ? -1 : cube;
}

// Gradient of the trilinear interpolant of one cell's corners at local position f in [0,1]^3:
// the normal where the wider central difference has a missing neighbour (edges of the model). In
// snorm16 steps (Voxel): the caller only needs its direction.
SEAMLESS_HD inline vec3 cell_gradient(const Voxel* const v[8], vec3 f) {
  vec3 g{0.f, 0.f, 0.f};
  for (int k = 0; k < 8; ++k) {
    int3 o = mc_corner(k);
    float wx = o.x ? f.x : 1.f - f.x, wy = o.y ? f.y : 1.f - f.y, wz = o.z ? f.z : 1.f - f.z;
    float sx = o.x ? 1.f : -1.f, sy = o.y ? 1.f : -1.f, sz = o.z ? 1.f : -1.f;
    g += vec3{sx * wy * wz, sy * wx * wz, sz * wx * wy} * static_cast<float>(v[k]->sdf16);
  }
  return g;
}

SEAMLESS_HD inline int3 cell_of(View<const int3> blocks, std::int64_t i) {
  int3 b = blocks[i / kBlockVoxels], l = local_coords(static_cast<int>(i % kBlockVoxels));
  return {b.x * 8 + l.x, b.y * 8 + l.y, b.z * 8 + l.z};
}

template <Executor Exec, class Acc>
std::int64_t TsdfExtract<Exec, Acc>::mesh_count(const Exec& ex, Acc a, View<const int3> blocks,
                                                const std::int8_t* table, View<std::int32_t> counts) {
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

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::sort_blocks(const Exec& ex, View<int3> blocks, View<HashKey> keys) {
  ex.for_each(blocks.size, [=] SEAMLESS_HD(std::int64_t i) { keys[i] = pack_block(blocks[i]); });
  ex.sort_by_key(keys.data, blocks.data, blocks.size, 3 * kCoordBits);
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::mesh_edges(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                                        View<const std::int32_t> offsets, View<std::uint64_t> edge_keys,
                                        View<std::int32_t> cells) {
  const std::int64_t n = blocks.size * kBlockVoxels;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    BlockCache c;
    const Voxel* v[8];
    const int3 g = cell_of(blocks, i);
    const int cube = mc_cube(a, g, c, v);
    if (cube <= 0) return;
    std::int64_t out = 3ll * offsets[i];
    for (int k = 0; k < kMcRow && table[cube * kMcRow + k] >= 0; ++k, ++out) {
      int e = table[cube * kMcRow + k], c0, c1;
      mc_edge(e, &c0, &c1);
      edge_keys[out] = edge_key(g + mc_corner(c0), e / 4);
      cells[out] = static_cast<std::int32_t>(i);
    }
  });
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::mesh_vertices(const Exec& ex, Acc a, View<const int3> blocks, const std::int8_t* table,
                                           View<const std::int32_t> offsets, View<const std::int32_t> cells,
                                           View<const std::int32_t> corners, View<vec3> positions, View<vec3> normals,
                                           View<uchar3> colors) {
  ex.for_each(corners.size, [=] SEAMLESS_HD(std::int64_t j) {
    const std::int64_t corner = corners[j], i = cells[corner];
    BlockCache c;
    const Voxel* v[8];
    const int3 g = cell_of(blocks, i);
    const int cube = mc_cube(a, g, c, v);  // > 0: the cell has this corner's triangle
    int c0, c1;
    const int e = table[cube * kMcRow + (corner - 3ll * offsets[i])];
    mc_edge(e, &c0, &c1);
    const float f0 = voxel_sdf(*v[c0], a.geom.truncation), f1 = voxel_sdf(*v[c1], a.geom.truncation);
    const float t = f0 / (f0 - f1);  // linear interpolation of the zero crossing along the edge
    const vec3 q = to_vec3(g + mc_corner(c0)) * (1.f - t) + to_vec3(g + mc_corner(c1)) * t;
    positions[j] = a.geom.to_world(q);
    bool complete = false;
    vec3 n = normalize(tsdf_gradient(a, q, 0.f, c, &complete));
    if (!complete) n = normalize(cell_gradient(v, q - to_vec3(g)));  // this cell's: one of up to four
    normals[j] = n;
    const uchar3 k0 = a.colors[v[c0] - a.voxels], k1 = a.colors[v[c1] - a.voxels];
    colors[j] = {static_cast<std::uint8_t>(k0.x * (1.f - t) + k1.x * t + 0.5f),
                 static_cast<std::uint8_t>(k0.y * (1.f - t) + k1.y * t + 0.5f),
                 static_cast<std::uint8_t>(k0.z * (1.f - t) + k1.z * t + 0.5f)};
  });
}

// ---- scene particles ---------------------------------------------------------------------------
// Why not the lattice points themselves: a lattice point is at most half a spacing from a surface
// only in the lucky case. A surface between two lattice planes (the demo's desk top, y = -0.62
// between -0.60 and -0.64 at 4 cm) is s/2 from both, and the fused TSDF there is the projective
// distance, which a camera looking at the desk top from 20 degrees above its plane stretches by
// 1 / sin(20 deg) ~ 3 (the TSDF is the depth difference along the camera's z, Newcombe et al.
// 2011 section 3.3; tsdf_fusion.inl), so both lattice points read about 1.5 s and neither was
// taken: the top had holes, and fluid leaked.
// So surface particles are put ON the fused surface instead: each lattice line (a row of lattice
// points along one axis) is searched for the zero crossings of the TSDF, and a crossing becomes a
// particle when the surface there faces along that axis (kAxisShare: the normal's largest
// component, or nearly). The crossings along the normal's axis sit one per lattice column, so a
// surface gets about one particle per spacing^2 whatever its height, and they form a grid of at
// most s x s*sqrt(2) cells (s * |n| / |n_axis| with |n_axis| >= |n| / sqrt(3)): every hole has a
// circumradius below one spacing, so a particle of diameter s cannot pass. Near-duplicates (edges,
// where two axes meet) are thinned afterwards (scene_particle_thin).

// Integer lattice coordinates of candidate i, or false when it falls outside its block (blocks own
// the lattice points p with floor((p - origin) / (8 s)) == b; the same float expression decides
// for both neighbours, so no point is taken twice or lost at a seam).
template <class Acc>
SEAMLESS_HD inline bool lattice_coords(const Acc& a, View<const int3> blocks, float spacing, std::int64_t i, int3* L) {
  const int m = lattice_per_block(a.geom.voxel_size, spacing);
  const std::int64_t m3 = static_cast<std::int64_t>(m) * m * m;
  int3 b = blocks[i / m3];
  int j = static_cast<int>(i % m3);
  int l[3] = {j % m, (j / m) % m, j / (m * m)}, bb[3] = {b.x, b.y, b.z}, r[3];
  float o[3] = {a.geom.origin.x, a.geom.origin.y, a.geom.origin.z};
  const float block = kBlockSide * a.geom.voxel_size;
  for (int k = 0; k < 3; ++k) {
    float lo = o[k] + bb[k] * block, hi = lo + block;
    int first = static_cast<int>(ceilf(lo / spacing)), end = static_cast<int>(ceilf(hi / spacing));
    if (first + l[k] >= end) return false;
    r[k] = first + l[k];
  }
  *L = {r[0], r[1], r[2]};
  return true;
}

// Steps per spacing when a lattice line is searched: samples at most one voxel apart, so that two
// consecutive samples bracket a crossing within the band where the TSDF is not truncated.
// (The 1e-4 keeps a spacing of exactly k voxels, give or take float rounding, at k steps.)
SEAMLESS_HD inline int line_steps(float voxel_size, float spacing) {
  int n = static_cast<int>(ceilf(spacing / voxel_size - 1e-4f));
  return n > 1 ? n : 1;
}

// World position of sample j (0..n) on the line from lattice point L along `axis`. The coordinate is
// (L n + j) * (s / n) on every axis, so sample n of L and sample 0 of its neighbour are the same
// float: a crossing at a lattice point is found once, by the segment that ends there.
SEAMLESS_HD inline vec3 line_sample(int3 L, int axis, int j, int n, float spacing) {
  const float h = spacing / static_cast<float>(n);
  int c[3] = {L.x * n, L.y * n, L.z * n};
  c[axis] += j;
  return {static_cast<float>(c[0]) * h, static_cast<float>(c[1]) * h, static_cast<float>(c[2]) * h};
}

// TSDF at world point p for the crossing search: false where unknown, and where truncated (a sign
// change between +mu and -mu is the seam behind a surface, not a surface; as mc_cube).
template <class Acc> SEAMLESS_HD inline bool band_sdf(const Acc& a, vec3 p, BlockCache& c, float* v) {
  return sample_tsdf(a, a.geom.to_voxel(p), c, v) && fabsf(*v) < 0.999f * a.geom.truncation;
}

// What the fused TSDF knows at a sample, for closing the unseen regions (see surface_crossings).
// kUnallocated: a corner's block was never allocated: no measurement came within the truncation of it
// (free space far from every surface, or never in view); kUnseen: the blocks exist (a surface was
// measured within a block of it) but a corner was never observed: in every view it was behind a
// surface by more than the truncation (tsdf_fusion.inl, fuse_voxel) or outside the image; kFree and
// kSolid: observed, the trilinear TSDF in *v is >= 0 or < 0.
enum SampleState : int { kUnallocated = 0, kUnseen = 1, kFree = 2, kSolid = 3 };

template <class Acc> SEAMLESS_HD inline int sample_state(const Acc& a, vec3 p, BlockCache& c, float* v) {
  const vec3 q = a.geom.to_voxel(p);
  const Voxel* corner[8];
  if (!cell_voxels(a, floor_to_int(q), c, corner)) return kUnallocated;
  for (int k = 0; k < 8; ++k)
    if (!voxel_observed(*corner[k])) return kUnseen;
  sample_tsdf(a, q, c, v);
  return *v < 0.f ? kSolid : kFree;
}

// Zero of the TSDF between p0 (value v0) and p1 (v1) of opposite signs: regula falsi. Along an axis
// the trilinear field is linear inside a cell; a segment of at most one voxel crosses at most one
// cell face, so two steps reach the zero of the piecewise-linear field to float rounding.
template <class Acc>
SEAMLESS_HD inline vec3 line_zero(const Acc& a, vec3 p0, float v0, vec3 p1, float v1, BlockCache& c) {
  vec3 x = p0;
  for (int it = 0; it < 3; ++it) {
    x = p0 + (p1 - p0) * (v0 / (v0 - v1));
    float vx;
    if (it == 2 || !band_sdf(a, x, c, &vx) || vx == 0.f) break;
    if ((vx < 0.f) == (v0 < 0.f)) p0 = x, v0 = vx;
    else p1 = x, v1 = vx;
  }
  return x;
}

// A crossing on a line along `axis` becomes a particle when the surface faces along that axis: the
// gradient's component there is at least kAxisShare of its largest one. 1 would be the dominant
// axis alone; a little less keeps a surface at 45 degrees from being dropped by both axes when
// float noise decides the tie (the thinning removes the pairs this creates).
constexpr float kAxisShare = 0.8f;

// Where candidates go (already offset to the first slot of this lattice point); null: count only.
// score = |n_axis|, how squarely the searched line meets the surface: the thinning keeps the higher.
struct CandidateOut {
  vec3* position;
  vec3* normal;
  float* score;
};

// Score of the particles that close unseen regions: below every surface particle (>= 1/sqrt(3) *
// kAxisShare), above the interior fill (0), so the thinning keeps a measured surface where both meet.
constexpr float kUnseenScore = 0.25f;

// Where observed free space meets space that no camera saw the scan has no surface, yet something
// hid that space from every view: the backs of the ball and the can on the demo's desk, and the desk
// behind and under them. Surfaces are open there, and a particle that enters the unseen space finds
// nothing under it: the demo's fluid fell through the desk inside the ball and the can
// (tests/app/demo_surfaces_test.py). So unseen space next to seen free space counts as solid, the
// conservative reading of a scan (what was never seen empty may be full), and each lattice line that
// passes from a free sample into unseen space gets a particle midway between the two samples, facing
// the free side. Samples are at most a voxel apart, as for the crossings, on all three axes, so the
// boundary gets particles at least as densely as a surface (the thinning removes near duplicates).
// Unseen: the sample's blocks exist but a corner voxel was never observed (behind a surface by more
// than the truncation in every view, tsdf_fusion.inl). Unallocated space is ambiguous: hashing
// allocates only the blocks around measured surfaces, so most free space is unallocated too, and its
// boundary with seen free space (the top of the blocks over a floor) is no surface. It counts as
// unseen only where the line, within one block, runs on from it into unseen space (the ball's hidden
// back: seen free above, a layer of unallocated blocks, then blocks behind its visible front).

// Whether the line from sample j (seen free) of lattice point L, stepping by dir (+-1) along axis,
// enters unseen space: an unseen sample, or unallocated ones up to a block long before an unseen one.
template <class Acc>
SEAMLESS_HD inline bool enters_unseen(const Acc& a, int3 L, int axis, int j, int dir, int n, float spacing,
                                      BlockCache& c) {
  const int reach = static_cast<int>(ceilf(kBlockSide * a.geom.voxel_size * n / spacing)) + 1;
  for (int k = 1; k <= reach; ++k) {
    float v = 0.f;
    const int st = sample_state(a, line_sample(L, axis, j + dir * k, n, spacing), c, &v);
    if (st == kUnseen) return true;
    if (st != kUnallocated) return false;
  }
  return false;
}

// The boundary particles of sample j (at p, state st, TSDF v) of lattice point L's segment along
// axis, towards its neighbours: sample j - 1 (state sm, at pm) and j + 1 (sp, at pp). A seen free
// sample next to unseen space gets a particle midway, facing the free side. So does a solid one
// within half a spacing of the surface (|v| < s/2, the near side of a band) whose surface lies in
// unseen space: the desk under the ball's overhang, seen from the side at a grazing angle, has its
// band but no free voxel over it; the particle goes where the TSDF puts the surface, at most one
// step on, facing the unseen side. (Deeper solid next to unseen space is the inner end of a band,
// no surface.) Each pair is found once, by the segment that owns sample j (j < n: sample n is the
// next segment's sample 0).
template <class Acc>
SEAMLESS_HD inline int unseen_boundaries(const Acc& a, int3 L, int axis, int j, int n, float spacing, int st, float v,
                                         vec3 p, vec3 pm, int sm, vec3 pp, int sp, BlockCache& c, CandidateOut out,
                                         int found) {
  const bool seen_free = st == kFree;
  if (!seen_free && !(st == kSolid && fabsf(v) < 0.5f * spacing)) return 0;
  const vec3 e{axis == 0 ? 1.f : 0.f, axis == 1 ? 1.f : 0.f, axis == 2 ? 1.f : 0.f};
  const float h = spacing / static_cast<float>(n);
  int k = 0;
  for (int dir = -1; dir <= 1; dir += 2) {
    const int nb = dir < 0 ? sm : sp;
    if (nb == kFree || nb == kSolid || !enters_unseen(a, L, axis, j, dir, n, spacing, c)) continue;
    if (out.position) {
      const vec3 q = dir < 0 ? pm : pp;
      out.position[found + k] = seen_free ? (p + q) * 0.5f : p + e * (static_cast<float>(dir) * fminf(fabsf(v), h));
      out.normal[found + k] = e * static_cast<float>(seen_free ? -dir : dir);
      out.score[found + k] = kUnseenScore;
    }
    ++k;
  }
  return k;
}

// The surface particles owned by lattice point L: crossings on the three segments L -> L + e_axis,
// and the boundaries of unseen space at their samples (unseen_boundaries).
// Writes them to out (unless out.position is null); returns how many there are.
template <class Acc> SEAMLESS_HD inline int surface_crossings(const Acc& a, int3 L, float spacing, CandidateOut out) {
  const int n = line_steps(a.geom.voxel_size, spacing);
  const float band = 0.999f * a.geom.truncation;  // as band_sdf
  BlockCache c;
  int found = 0;
  for (int axis = 0; axis < 3; ++axis) {
    vec3 pm = line_sample(L, axis, -1, n, spacing), p0 = line_sample(L, axis, 0, n, spacing);
    float vm = 0.f, v0 = 0.f;
    int sm = sample_state(a, pm, c, &vm), s0 = sample_state(a, p0, c, &v0);
    bool ok0 = s0 >= kFree && fabsf(v0) < band;
    for (int j = 1; j <= n; ++j) {
      vec3 p1 = line_sample(L, axis, j, n, spacing);
      float v1 = 0.f;
      int s1 = sample_state(a, p1, c, &v1);
      bool ok1 = s1 >= kFree && fabsf(v1) < band;
      found += unseen_boundaries(a, L, axis, j - 1, n, spacing, s0, v0, p0, pm, sm, p1, s1, c, out, found);
      if (ok0 && ok1 && (v0 < 0.f) != (v1 < 0.f)) {
        vec3 x = line_zero(a, p0, v0, p1, v1, c);
        float vx = 0.f;
        sample_tsdf(a, a.geom.to_voxel(x), c, &vx);
        vec3 g = tsdf_gradient(a, a.geom.to_voxel(x), vx, c);
        float ga[3] = {fabsf(g.x), fabsf(g.y), fabsf(g.z)}, gl = length(g);
        float gmax = fmaxf(ga[0], fmaxf(ga[1], ga[2]));
        if (gl > 0.f && ga[axis] >= kAxisShare * gmax) {
          if (out.position) out.position[found] = x, out.normal[found] = g / gl, out.score[found] = ga[axis] / gl;
          ++found;
        }
      }
      pm = p0, sm = s0, p0 = p1, v0 = v1, ok0 = ok1, s0 = s1;
    }
  }
  return found;
}

// The optional solid fill stays on the lattice: a lattice point at least s/2 below the fused surface
// (so at least s/2 from the surface particles where the TSDF is the true distance, and farther where
// it is a stretched projective one) down to interior_depth, as far as the truncated TSDF knows it.
template <class Acc>
SEAMLESS_HD inline bool interior_point(const Acc& a, int3 L, float spacing, float interior_depth, vec3* p,
                                       vec3* normal) {
  if (!(interior_depth > 0.f)) return false;
  *p = line_sample(L, 0, 0, 1, spacing);
  float v;
  vec3 g{0.f, 0.f, 0.f};
  if (!sample_sdf(a, *p, &v, &g) || v > -0.5f * spacing || v < -interior_depth) return false;
  *normal = length(g) > 0.f ? normalize(g) : vec3{0.f, 0.f, 0.f};
  return true;
}

template <Executor Exec, class Acc>
std::int64_t TsdfExtract<Exec, Acc>::scene_particle_count(const Exec& ex, Acc a, View<const int3> blocks, float spacing,
                                                          float interior_depth, View<std::int32_t> counts) {
  ex.for_each(counts.size, [=] SEAMLESS_HD(std::int64_t i) {
    int3 L;
    vec3 p, nrm;
    int k = 0;
    if (lattice_coords(a, blocks, spacing, i, &L))
      k = surface_crossings(a, L, spacing, CandidateOut{nullptr, nullptr, nullptr}) +
          (interior_point(a, L, spacing, interior_depth, &p, &nrm) ? 1 : 0);
    counts[i] = k;
  });
  return ex.exclusive_scan(counts.data, counts.data, counts.size);
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::scene_particle_emit(const Exec& ex, Acc a, View<const int3> blocks, float spacing,
                                                 float interior_depth, View<const std::int32_t> offsets,
                                                 View<vec3> positions, View<vec3> normals, View<float> scores) {
  ex.for_each(offsets.size, [=] SEAMLESS_HD(std::int64_t i) {
    int3 L;
    if (!lattice_coords(a, blocks, spacing, i, &L)) return;
    const std::int64_t first = offsets[i];
    const std::int64_t k = surface_crossings(
        a, L, spacing, CandidateOut{positions.data + first, normals.data + first, scores.data + first});
    vec3 p, nrm;
    if (interior_point(a, L, spacing, interior_depth, &p, &nrm))
      positions[first + k] = p, normals[first + k] = nrm, scores[first + k] = 0.f;  // surface ones win thinning
  });
}

// ---- thinning: no two scene particles closer than min_distance ----------------------------------
// Where two lines meet one surface patch (box edges and corners, concave seams, the 45-degree ties
// of kAxisShare) their crossings can nearly coincide. Each candidate looks at the candidates within
// min_distance (cells of that side, the 27 around its own, found by binary search in the sorted
// cell keys) and is dropped when one of them outranks it. Of every close pair the lower one goes,
// so no close pair survives; a dropped candidate is within min_distance of one that outranks it,
// which in turn is kept or within min_distance of a higher one, and so on up a chain that ends.

// Cell of p on a grid of side r, packed 21 bits a coordinate (+-2^20 cells: +-1 km at 1 mm cells).
SEAMLESS_HD inline std::uint64_t thin_cell_key(int3 c) {
  const std::uint64_t m = (1ull << 21) - 1ull, bias = 1ull << 20;
  return (((std::uint64_t(c.x) + bias) & m) << 42) | (((std::uint64_t(c.y) + bias) & m) << 21) |
         ((std::uint64_t(c.z) + bias) & m);
}

// First index in the sorted keys[0, n) whose key is not less than k.
SEAMLESS_HD inline std::int64_t lower_bound_key(const std::uint64_t* keys, std::int64_t n, std::uint64_t k) {
  std::int64_t lo = 0, hi = n;
  while (lo < hi) {
    std::int64_t mid = lo + (hi - lo) / 2;
    if (keys[mid] < k) lo = mid + 1;
    else hi = mid;
  }
  return lo;
}

// Whether candidate j outranks candidate i: the higher score, then the lexicographically smaller
// position, then the smaller index. A strict total order that does not depend on the candidates'
// order (which follows the hash table's slots) except for exact duplicates.
SEAMLESS_HD inline bool outranks(vec3 pj, float sj, std::int64_t j, vec3 pi, float si, std::int64_t i) {
  if (sj != si) return sj > si;
  if (pj.x != pi.x) return pj.x < pi.x;
  if (pj.y != pi.y) return pj.y < pi.y;
  if (pj.z != pi.z) return pj.z < pi.z;
  return j < i;
}

template <Executor Exec, class Acc>
std::int64_t TsdfExtract<Exec, Acc>::scene_particle_thin(const Exec& ex, View<const vec3> positions,
                                                         View<const float> scores, float min_distance,
                                                         View<std::uint64_t> keys, View<std::int32_t> order,
                                                         View<std::int32_t> keep) {
  const std::int64_t n = positions.size;
  const float r = min_distance;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    keys[i] = thin_cell_key(floor_to_int(positions[i] / r));
    order[i] = static_cast<std::int32_t>(i);
  });
  ex.sort_by_key(keys.data, order.data, n, 63);
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t k) {
    const std::int64_t i = order[k];
    const vec3 p = positions[i];
    const int3 c = floor_to_int(p / r);
    bool drop = false;
    for (int d = 0; d < 27 && !drop; ++d) {
      const std::uint64_t key = thin_cell_key(c + int3{d % 3 - 1, (d / 3) % 3 - 1, d / 9 - 1});
      for (std::int64_t m = lower_bound_key(keys.data, n, key); m < n && keys[m] == key && !drop; ++m) {
        const std::int64_t j = order[m];
        const vec3 q = positions[j];
        drop = j != i && dot(q - p, q - p) < r * r && outranks(q, scores[j], j, p, scores[i], i);
      }
    }
    keep[i] = drop ? 0 : 1;
  });
  return ex.exclusive_scan(keep.data, keep.data, n);
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::scene_particle_compact(const Exec& ex, View<const std::int32_t> offsets, std::int64_t kept,
                                                    View<const vec3> positions, View<const vec3> normals,
                                                    View<vec3> out_positions, View<vec3> out_normals) {
  const std::int64_t n = offsets.size;
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t next = i + 1 < n ? offsets[i + 1] : kept;
    if (next == offsets[i]) return;
    out_positions[offsets[i]] = positions[i];
    out_normals[offsets[i]] = normals[i];
  });
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::sample_sdf_grid(const Exec& ex, Acc a, vec3 origin, int3 dims, float voxel, float unknown,
                                             View<float> out) {
  ex.for_each(out.size, [=] SEAMLESS_HD(std::int64_t i) {
    const std::int64_t plane = static_cast<std::int64_t>(dims.x) * dims.y;
    int z = static_cast<int>(i / plane), y = static_cast<int>((i % plane) / dims.x), x = static_cast<int>(i % dims.x);
    vec3 p = origin + vec3{float(x), float(y), float(z)} * voxel;
    float v;
    out[i] = sample_sdf(a, p, &v, nullptr) ? v : unknown;
  });
}

template <Executor Exec, class Acc>
void TsdfExtract<Exec, Acc>::slot_block_coords(const Exec& ex, HashTableView t, View<const std::int32_t> slots,
                                               View<int3> out) {
  ex.for_each(slots.size, [=] SEAMLESS_HD(std::int64_t i) { out[i] = unpack_block(t.keys[slots[i]]); });
}

}  // namespace seamless::kernels
