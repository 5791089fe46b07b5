// Per-element math of the particle solver (host and device): SPH kernels, the neighbour grid's
// cell keys and traversal, and the rotation extraction of shape matching. The phase flags
// (core/phase.hpp) and quaternions (core/quaternion.hpp) are in core: the renderer reads them too.
#pragma once
#include <cstdint>
#include <cstring>

#include "core/hd.hpp"
#include "core/math.hpp"
#include "core/phase.hpp"
#include "core/quaternion.hpp"

namespace seamless::kernels {

constexpr float kPi = 3.14159265358979f;

// c ? a : b, for code written once over a float type (SphKernel): the SIMD lanes of the CPU
// (core/simd.hpp) select lane by lane.
SEAMLESS_HD inline float select(bool c, float a, float b) { return c ? a : b; }
SEAMLESS_HD inline int select(bool c, int a, int b) { return c ? a : b; }
SEAMLESS_HD inline vec3 select(bool c, vec3 a, vec3 b) { return c ? a : b; }
// The square root of such code (sqrtf for float: no promotion to double).
SEAMLESS_HD inline float fsqrt(float x) { return sqrtf(x); }

// A position (or vector) and one more word, 16-byte aligned: what a neighbour loop gathers from
// neighbour j in one 128-bit load on CUDA (a vec3 and a float are four 32-bit loads, four times
// the L1 requests of a gather whose 32 lanes hit 32 different sectors). The kernels keep packed
// copies of what each neighbour pass reads (SimViews::spk, spl, svh, cnv).
struct alignas(16) Packed {
  float x, y, z, w;
  SEAMLESS_HD vec3 xyz() const { return {x, y, z}; }
  SEAMLESS_HD std::uint32_t bits() const { return static_cast<std::uint32_t>(float_bits(w)); }  // a phase in w
  SEAMLESS_HD static Packed of(vec3 v, float w) { return {v.x, v.y, v.z, w}; }
  SEAMLESS_HD static Packed of_phase(vec3 v, std::uint32_t ph) {
    return {v.x, v.y, v.z, bits_float(static_cast<std::int32_t>(ph))};
  }
};

// SPH kernels of smoothing radius h with their normalising constants computed once (the
// constants cost two divisions per call otherwise, and the kernels run for every neighbour pair
// several times per iteration). Same expressions, same float results as evaluating them inline.
struct SphKernel {
  float h = 0.f, h2 = 0.f;
  float poly6_c = 0.f;   // 315 / (64 pi h^9)
  float spiky_c = 0.f;   // -45 / (pi h^6)
  float akinci_c = 0.f;  // 32 / (pi h^9)
  float h6_64 = 0.f;     // h^6 / 64

  SEAMLESS_HD static SphKernel make(float h) {
    SphKernel k;
    float h2 = h * h;
    k.h = h, k.h2 = h2;
    k.poly6_c = 315.f / (64.f * kPi * h2 * h2 * h2 * h2 * h);
    k.spiky_c = -45.f / (kPi * h * h * h * h * h * h);
    k.akinci_c = 32.f / (kPi * h * h * h * h * h * h * h * h * h);
    k.h6_64 = h * h * h * h * h * h / 64.f;
    return k;
  }

  // The kernels are templates over the float type F (float, or the CPU's SIMD lanes simd::vf,
  // with V its vec3) with selects instead of early returns; for float the same results as the
  // early returns.

  // Poly6 (Mueller 2003, used for density in Macklin & Mueller 2013, eq. 2).
  template <class F> SEAMLESS_HD F poly6(F r2) const {
    const F t = h2 - r2;
    return select(r2 < h2, poly6_c * t * t * t, F(0.f));
  }

  // Gradient of the spiky kernel with respect to p_i for r = p_i - p_j (Mueller 2003; PBF eq. 8).
  template <class V> SEAMLESS_HD V spiky_grad(V r) const {
    const auto l = length(r);
    const auto t = h - l;
    return select((l < h) & (l > 1e-12f), r * (spiky_c * t * t / l), V{});
  }

  // Akinci 2013 cohesion spline C(r) (eq. 2 there), zero beyond h.
  template <class F> SEAMLESS_HD F akinci(F r) const {
    const F a = (h - r) * (h - r) * (h - r) * r * r * r;
    const F c = select(2.f * r > h, akinci_c * a, akinci_c * (2.f * a - h6_64));
    return select((r < h) & (r > 0.f), c, F(0.f));
  }
};

SEAMLESS_HD inline float poly6(float r2, float h) { return SphKernel::make(h).poly6(r2); }
SEAMLESS_HD inline vec3 spiky_grad(vec3 r, float h) { return SphKernel::make(h).spiky_grad(r); }
SEAMLESS_HD inline float akinci_spline(float r, float h) { return SphKernel::make(h).akinci(r); }

// ---- neighbour grid -------------------------------------------------------------------------
// Cells come from seamless::floor_int (src/core/math.hpp), which holds x within +-1e9 first: a
// particle that has flown off to infinity, or a NaN, gets a far cell (wrapped by the periodic grid
// anyway) instead of an undefined conversion.

// A periodic uniform grid of 2^bits cells per axis: cell coordinates wrap, so the grid covers all
// of space, and with at least 2 * reach + 1 cells per axis the cells around a particle are
// distinct buckets (no particle is visited twice). Far-apart particles may share a bucket; the
// distance test removes them. Cells are half the search radius (reach 2): the rows of cells
// searched then hug the search sphere (see for_each_in_radius), about 100 candidates per particle
// at the fluid rest spacing instead of the 216 of 27 cells of one search radius.
struct GridSpec {
  float inv_cell;                  // 1 / cell size
  int bits;                        // cells per axis = 1 << bits
  float cell;                      // cell size
  static constexpr int reach = 2;  // cells searched on each side: search radius / cell
  SEAMLESS_HD std::uint32_t key(int3 c) const {
    std::uint32_t m = (1u << bits) - 1u;
    return (static_cast<std::uint32_t>(c.x) & m) | ((static_cast<std::uint32_t>(c.y) & m) << bits) |
           ((static_cast<std::uint32_t>(c.z) & m) << (2 * bits));
  }
  SEAMLESS_HD int3 cell_of(vec3 p) const {
    return {floor_int(p.x * inv_cell), floor_int(p.y * inv_cell), floor_int(p.z * inv_cell)};
  }
  SEAMLESS_HD std::int64_t cells() const { return std::int64_t{1} << (3 * bits); }
  // Grid of cells of half the search radius R.
  static GridSpec for_radius(float R, int bits) { return {2.f / R, bits, 0.5f * R}; }
  // Cells per axis (as bits) for n points: about 16 cells a point, 8..128 per axis (at least 5 per
  // axis keeps the cells searched around a point distinct). Cells are half the search radius, so a
  // particle at the fluid rest spacing fills about one; the spare cells make the periodic grid wide
  // enough that spread-out scenes (a sheet of cloth, bodies far apart) do not fold many far-away
  // particles into the cells searched.
  static int bits_for(std::int64_t n) {
    int bits = 3;
    while (bits < 7 && (std::int64_t{1} << (3 * bits)) < 16 * n) ++bits;
    return bits;
  }
};

// Distance along one axis from coordinate v to cell i's slab [i cs, (i + 1) cs), made smaller by
// pad so that rounding never drops a cell that holds a neighbour.
// F: float, or the CPU's SIMD lanes.
template <class F> SEAMLESS_HD inline F slab_gap(F v, int i, float cs, float pad) {
  const float lo = static_cast<float>(i) * cs;
  const F a = lo - v, b = v - (lo + cs);  // at most one is > 0
  const F g = select(a > b, a, b) - pad;  // max, without a branch
  return select(g > 0.f, g, F(0.f));
}

// The squared distances along y and along z from p (in cell c) to the slabs of cells c.y + d - reach
// and c.z + d - reach, d in [0, 2 reach], made smaller by pad: a row of cells (dy, dz) is at
// squared y-z distance ey2[dy] + ez2[dz] (for_each_run_in_radius).
SEAMLESS_HD inline void slab_gaps2(const GridSpec& g, vec3 p, int3 c, float pad, float* ey2, float* ez2) {
  constexpr int kReach = GridSpec::reach;
  for (int d = 0; d <= 2 * kReach; ++d) {
    const float ey = slab_gap(p.y, c.y + d - kReach, g.cell, pad), ez = slab_gap(p.z, c.z + d - kReach, g.cell, pad);
    ey2[d] = ey * ey, ez2[d] = ez * ez;
  }
}

// The cells [lo, hi] along x (not yet wrapped) of the row of cells at squared y-z distance d2
// from p that the sphere of radius R2 = R^2 around p crosses, within reach of p's cell cx, made
// larger by pad (for_each_run_in_radius). F, I: float and int, or the CPU's SIMD lanes.
template <class F, class I>
SEAMLESS_HD inline void row_cells(const GridSpec& g, F px, I cx, float R2, float pad, F d2, I& lo, I& hi) {
  // Lanes of rows the sphere misses (d2 >= R2, skipped by the callers) take a square root of 0, not
  // of a negative number: a NaN there made floor_int's conversion overflow (UBSan).
  const F q = R2 - d2;
  const F rx = fsqrt(select(q > 0.f, q, F(0.f))) + pad;
  const I a = floor_int((px - rx) * g.inv_cell), b = floor_int((px + rx) * g.inv_cell);
  lo = select(a > cx - GridSpec::reach, a, I(cx - GridSpec::reach));
  hi = select(b < cx + GridSpec::reach, b, I(cx + GridSpec::reach));
}

// Calls fn(a, e) for every run [a, e) of grid entries in the cells that can hold a point within
// R of p. For each row of cells along x (fixed y, z within reach) only the x range that the
// sphere of radius R crosses at the row's nearest y-z distance is visited. Keys run along x within
// a row, so that range is one run of the sorted entries, [start[first cell], start[last cell + 1])
// (start[k] = number of entries with key < k, k in [0, cells]), or two where it wraps around the
// grid; a row without entries there gives an empty run. The runs depend only on p and the grid:
// lanes that share p get the same runs (a group of for_each_grouped may split each run).
// Candidates still need the distance test. The squared slab distances along y and z are the same
// for a whole slab of rows, so they are computed once per slab (5 + 5 instead of 25 + 25).
template <class F>
SEAMLESS_HD inline void for_each_run_in_radius(const GridSpec& g, const int* start, vec3 p, float R, F&& fn) {
  constexpr int kReach = GridSpec::reach, kWidth = 2 * kReach + 1;
  const int3 c = g.cell_of(p);
  const float R2 = R * R, pad = 1e-3f * g.cell;
  const std::uint32_t m = (1u << g.bits) - 1u;
  float ey2[kWidth], ez2[kWidth];
  slab_gaps2(g, p, c, pad, ey2, ez2);
  for (int dz = 0; dz < kWidth; ++dz) {
    const std::uint32_t slab = (static_cast<std::uint32_t>(c.z + dz - kReach) & m) << (2 * g.bits);
    for (int dy = 0; dy < kWidth; ++dy) {
      const float d2 = ey2[dy] + ez2[dz];
      if (d2 >= R2) continue;
      const std::uint32_t row = ((static_cast<std::uint32_t>(c.y + dy - kReach) & m) << g.bits) | slab;
      int lo, hi;
      row_cells(g, p.x, c.x, R2, pad, d2, lo, hi);
      const std::uint32_t x0 = static_cast<std::uint32_t>(lo) & m, x1 = static_cast<std::uint32_t>(hi) & m;
      if (x0 <= x1) {
        fn(start[row | x0], start[(row | x1) + 1]);
      } else {  // the x range wraps: [x0, m] and [0, x1]
        fn(start[row | x0], start[(row | m) + 1]);
        fn(start[row], start[(row | x1) + 1]);
      }
    }
  }
}

// Calls fn(j) for every grid entry j of the runs above.
template <class F>
SEAMLESS_HD inline void for_each_in_radius(const GridSpec& g, const int* start, vec3 p, float R, F&& fn) {
  for_each_run_in_radius(g, start, p, R, [&](int a, int e) {
    for (int j = a; j < e; ++j) fn(j);
  });
}

// start[k] for the sorted keys: the number of keys below k (lower bound), k in [0, cells].
// Branch-free (the comparison selects the half arithmetically): its outcome is random.
SEAMLESS_HD inline int lower_bound_key(const std::uint32_t* keys, int n, std::uint32_t k) {
  int lo = 0, len = n;
  while (len > 0) {
    int half = len >> 1;
    int right = keys[lo + half] < k;
    lo += right * (half + 1);
    len = half + right * (len - 2 * half - 1);
  }
  return lo;
}

// ---- shape matching's rotation ------------------------------------------------------------------
// Rotational part of A (Mueller, Bender, Chentanez, Macklin 2016, "A Robust Method to Extract the
// Rotational Part of Deformations", eq. 7): rotate q towards the column-wise alignment of R(q)
// with A until the angular step is negligible. Warm-started from the previous frame's q, it needs
// few iterations and never fails on flat or inverted A, unlike a closed-form polar decomposition.
SEAMLESS_HD inline vec4 extract_rotation(const mat3& A, vec4 q, int max_iter) {
  for (int it = 0; it < max_iter; ++it) {
    mat3 R = quat_to_mat(q);
    vec3 num = cross(R.col(0), A.col(0)) + cross(R.col(1), A.col(1)) + cross(R.col(2), A.col(2));
    float den = fabsf(dot(R.col(0), A.col(0)) + dot(R.col(1), A.col(1)) + dot(R.col(2), A.col(2))) + 1e-9f;
    vec3 omega = num / den;
    float w = length(omega);
    if (w < 1e-9f) break;
    vec3 axis = omega / w;
    float s = sinf(0.5f * w);
    q = quat_normalize(quat_mul(vec4{axis.x * s, axis.y * s, axis.z * s, cosf(0.5f * w)}, q));
  }
  return q;
}

}  // namespace seamless::kernels
