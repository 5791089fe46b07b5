// Kernel bodies for physics/solver.hpp, compiled once per backend.
#include <type_traits>
#include <vector>

#include "core/atomics.hpp"
#include "core/exec.hpp"
#include "kernels/physics/constraints.hpp"
#include "kernels/physics/simd.hpp"
#include "kernels/physics/solver.hpp"

// Full unrolling of a loop over a register array (CUDA; GCC would warn on the pragma).
#if defined(__CUDA_ARCH__)
#define SEAMLESS_PHYS_UNROLL _Pragma("unroll")
#else
#define SEAMLESS_PHYS_UNROLL
#endif

namespace seamless::kernels {

#if !defined(__CUDACC__)
// The CPU's SIMD tiles (defined at the end of this file).
#if SEAMLESS_SIMD_X86
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace detail {
bool vorticity_tile(const SimViews& S, int s0);
bool density_tile(const SimViews& S, int s0);
bool solve_tile(const SimViews& S, int s0);
bool forces_tile(const SimViews& S, int s0);
int scan_candidates_simd(const SimViews& S, vec3 p, float R2, int s, const int* run, int nruns, int* list, int cap);
int scan_runs_simd(const SimViews& S, vec3 p, float R, int s, int* list, int cap);
bool neighbors_tile(const SimViews& S, int s0);
}  // namespace detail
#if SEAMLESS_SIMD_X86
#pragma GCC pop_options
#endif

namespace detail {
}  // namespace detail

// Runs tile(S, s0) for the tiles of 8 particles and one(s) for the particles of tiles it
// declines, on the CPU when the SIMD lanes are available; false otherwise (the caller then runs
// its loop). Each tile is taken by the task of its first particle (for_each's threshold and
// schedule stay those of the particles).
template <class Exec, class Tile, class One>
bool cpu_tiles(const Exec& ex, const SimViews& S, Tile tile, One one) {
  if constexpr (Exec::device != Device::CPU) return false;
  if (!simd::cpu_simd()) return false;
  ex.for_each(S.n, [=](std::int64_t i) {
    if (i % simd::kWidth != 0) return;
    const int s0 = static_cast<int>(i);
    if (tile(S, s0)) return;
    for (int s = s0, e = s0 + simd::kWidth < S.n ? s0 + simd::kWidth : S.n; s < e; ++s) one(s);
  });
  return true;
}
#endif

namespace detail {

SEAMLESS_HD inline int max(int a, int b) { return a > b ? a : b; }

SEAMLESS_HD inline bool both_fluid(std::uint32_t a, std::uint32_t b) {
  return phase::is(a, phase::kFluid) && phase::is(b, phase::kFluid);
}

// Whether prepare_constraints keeps each pair's kernel values for solve_contacts_fluid
// (SimViews::pair_w): on the CPU, where recomputing them (position gather, square root,
// division: ~25 instructions a pair) costs more than storing and reloading 16 bytes from cache;
// not on CUDA, where that would be ~0.5 GB of extra memory traffic per iteration at 1M particles
// against arithmetic a latency-bound kernel gets almost for free.
template <class Exec>
inline constexpr bool kCachePairs = Exec::device == Device::CPU;

// Calls use(k, gather(j)) with j = list[k * col] for a lane's entries k = g.lane,
// g.lane + g.size, ... below m, in k order (sums keep the order of a plain loop). gather(j)
// loads what the pair needs of neighbour j; use does the math. On CUDA the entries come in
// batches of kPairBatch: their indices, then all their gathers, then the math. At 1M particles
// CUDA runs one thread per particle, whose pair loop was a chain of dependent loads (index, then
// the neighbour's data) per entry, and the passes were latency-bound (Nsight showed few active
// warps and little DRAM bandwidth used); the math cannot be relied on to leave loads free
// to move (IEEE square roots and divisions have slow-path branches), so the batch is explicit.
// On the CPU one entry at a time (kPairBatch 1), the plain loop.
// Batch sizes (CUDA) of the passes that gather one packed word per pair (density, PBF) and two
// (vorticity, forces: 8 more registers per entry of a batch; at 4 the two velocity passes took
// 71 and 80 registers, 3 blocks of 256 threads per multiprocessor, and ran slower than at 2).
#ifndef SEAMLESS_BATCH1
#define SEAMLESS_BATCH1 4
#endif
#ifndef SEAMLESS_BATCH2
#define SEAMLESS_BATCH2 2
#endif
#if defined(__CUDA_ARCH__)
constexpr int kPairBatch1 = SEAMLESS_BATCH1, kPairBatch2 = SEAMLESS_BATCH2;
#else
constexpr int kPairBatch1 = 1, kPairBatch2 = 1;
#endif
// Blocks of the executor's threads that the heavy pair passes (prepare_constraints,
// solve_contacts_fluid, velocity_effects) ask to keep resident per multiprocessor (a register cap
// on CUDA, MinBlocks; 0: none). 5 (48 registers, a few spilled bytes in two passes) was faster
// than none on fluid_1m and fluid_10k and no slower on the other scenes (docs/PERFORMANCE.md).
#ifndef SEAMLESS_PAIR_MIN_BLOCKS
#define SEAMLESS_PAIR_MIN_BLOCKS 5
#endif
constexpr MinBlocks<SEAMLESS_PAIR_MIN_BLOCKS> kPairOccupancy{};
template <int kPairBatch, class Gather, class Use>
SEAMLESS_HD inline void for_each_entry(const int* list, std::int64_t col, int m, Lanes g, Gather&& gather, Use&& use) {
  using D = decltype(gather(0));
  const int d = g.size;
  const std::int64_t step = d * col;  // from one of the lane's entries to the next
  int k = g.lane;
  const int* at = list + k * col;  // entry k (a pointer: (k + u d) col took 64-bit multiplies per entry)
  if constexpr (kPairBatch > 1) {
    for (; k + (kPairBatch - 1) * d < m; k += kPairBatch * d, at += kPairBatch * step) {
      int j[kPairBatch];
      D v[kPairBatch];
      SEAMLESS_PHYS_UNROLL
      for (int u = 0; u < kPairBatch; ++u) j[u] = at[u * step];
      SEAMLESS_PHYS_UNROLL
      for (int u = 0; u < kPairBatch; ++u) v[u] = gather(j[u]);
      SEAMLESS_PHYS_UNROLL
      for (int u = 0; u < kPairBatch; ++u) use(k + u * d, v[u]);
    }
  }
  for (; k < m; k += d, at += step) {
    const int j = *at;
    use(k, gather(j));
  }
}

// What a pair loop gathers of neighbour j: one or two packed words and whether j is fluid.
struct Gather1 {
  Packed a;
  bool fluid;
};
struct Gather2 {
  Packed a, b;
  bool fluid;
};

// The pair math of the fluid passes with one reciprocal square root on CUDA: SphKernel's
// spiky gradient and the cohesion factor take |r| by an IEEE square root and divide by it, and
// the symmetrising factor is a division; on CUDA each compiles to a multi-instruction sequence
// with a slow-path branch, and at 1M particles the pair passes are bound by instruction issue
// (Nsight: prepare_constraints, solve_contacts_fluid). rsqrtf and __fdividef are
// the hardware approximations (2 ulp, CUDA programming guide, table of intrinsic functions),
// far below the CPU/CUDA tolerance of PhysicsParity (FMA contraction and sum order differ
// already). The CPU keeps the IEEE forms: its results are unchanged.
// V is vec3 on CUDA and vec3 or the CPU's SIMD lanes on the CPU (F their float), which keeps the
// IEEE forms.
// On CUDA the reciprocal square root skips rsqrtf's denormal fix-up (four instructions a pair),
// which an argument above 1e-24 never needs (PTX rsqrt.approx.ftz: the same hardware result for
// normal arguments). The pair math keeps its early returns: selects instead (every pair's math
// done, no branch) were slower at 1M particles (docs/PERFORMANCE.md).
#if defined(__CUDA_ARCH__)
__device__ inline float rsqrt_normal(float x) {
  float r;
  asm("rsqrt.approx.ftz.f32 %0, %1;" : "=f"(r) : "f"(x));
  return r;
}
#endif
template <class V>
SEAMLESS_HD inline V pair_grad(const SphKernel& W, V r) {
#if defined(__CUDA_ARCH__)
  const float l2 = length2(r);
  if (l2 >= W.h2 || l2 <= 1e-24f) return {0.f, 0.f, 0.f};  // l >= h or l <= 1e-12, as spiky_grad
  const float il = rsqrt_normal(l2), t = W.h - l2 * il;
  return r * (W.spiky_c * t * t * il);
#else
  return W.spiky_grad(r);
#endif
}
template <class F>
SEAMLESS_HD inline F fast_div(float a, F b) {
#if defined(__CUDA_ARCH__)
  return __fdividef(a, b);
#else
  return a / b;
#endif
}

// spk = (sp, phase bits): the packed copy that the next neighbour loops gather (Packed).
template <class Exec>
void pack_positions(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) { S.spk[s] = Packed::of_phase(S.sp[s], S.sphase[s]); });
}

// Pairs that never interact are left out of the lists: particles of one rigid body, and
// particles of one cloth unless it collides with itself (then only pairs that are not already
// close in the rest shape, which the stretch constraints keep apart anyway).
SEAMLESS_HD inline bool may_interact(const SimViews& S, std::uint32_t pi, std::uint32_t pj, int si, int sj) {
  using namespace phase;
  if (is(pi, kRigid) && is(pj, kRigid) && group(pi) == group(pj)) return false;
  if (is(pi, kCloth) && is(pj, kCloth) && group(pi) == group(pj)) {
    if (!is(pi, kSelfCollide)) return false;
    float e = S.c.cloth_self_exclusion;
    return length2(S.rest[S.order[si]] - S.rest[S.order[sj]]) >= e * e;
  }
  return true;
}

struct PairGeom {
  bool hit;
  vec3 n;  // unit, pushes particle s away from j
  float depth;
};

// Contact between dynamic particles s and j at positions P (Macklin 2014, eq. 4.3 of the
// dissertation). Between two rigid bodies whose particles are both below the surface layer, the
// bodies have interpenetrated deeply; the stored SDF of the shallower particle then gives the
// direction and depth (Macklin 2014, section 5), so the bodies separate the short way.
SEAMLESS_HD inline PairGeom pair_geometry(const SimViews& S, int s, int j, const vec3* P) {
  const float D = S.c.diameter;
  vec3 d = P[s] - P[j];
  float l2 = length2(d);
  if (l2 >= D * D) return {false, {0.f, 0.f, 0.f}, 0.f};
  float l = sqrtf(l2);
  PairGeom g{true, l > 1e-9f ? d / l : vec3{0.f, 1.f, 0.f}, D - l};
  std::uint32_t pi = S.sphase[s], pj = S.sphase[j];
  if (phase::is(pi, phase::kRigid) && phase::is(pj, phase::kRigid) && S.rsdf) {
    const int idi = S.order[s], idj = S.order[j];
    vec4 gi = S.rsdf[idi], gj = S.rsdf[idj];
    float ai = fabsf(gi.w), aj = fabsf(gj.w);
    if (fminf(ai, aj) > D) {
      // Both particles of the pair must pick the same SDF (ties broken by id), so that their
      // corrections stay opposite.
      if (ai < aj || (ai == aj && idi < idj)) g = {true, -(S.body_R[phase::group(pi)] * xyz(gi)), ai};
      else g = {true, S.body_R[phase::group(pj)] * xyz(gj), aj};
    }
  }
  return g;
}

// Entries of s's particle list that can be contacts: none for a fluid particle whose list holds
// only fluid (fluids meet through the density constraint), so its loops are skipped.
SEAMLESS_HD inline int contact_list_len(const SimViews& S, int s) {
  return phase::is(S.sphase[s], phase::kFluid) && S.nsolid[s] == 0 ? 0 : S.nnbr[s];
}

// Particle and scene-particle contacts of one lane's share of s's lists, and the sum of the scene
// contact normals there (summed over the lanes with Lanes::sum).
struct ContactCount {
  int count, scene;
  vec3 sn;
};
SEAMLESS_HD inline ContactCount operator+(const ContactCount& a, const ContactCount& b) {
  return {a.count + b.count, a.scene + b.scene, a.sn + b.sn};
}

// Number of active contacts of particle s at positions P (at least 1: it divides), in lane 0 (the
// lanes of g split s's lists). A rigid particle touching the scene also counts itself in its
// body's body_contacts.
SEAMLESS_HD inline int count_contacts(const SimViews& S, int s, const vec3* P, Lanes g) {
  const float D2 = S.c.diameter * S.c.diameter;
  const int m = contact_list_len(S, s), ms = S.nsnbr[s];
  const vec3 p = P[s];
  ContactCount c{0, 0, {0.f, 0.f, 0.f}};
  for (int k = g.lane; k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    if (both_fluid(S.sphase[s], S.sphase[j])) continue;
    if (length2(p - P[j]) < D2) ++c.count;
  }
  for (int k = g.lane; k < ms; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    float l2 = length2(r);
    if (l2 < D2) {
      ++c.scene;
      if (l2 > 1e-18f) c.sn += r / sqrtf(l2);
    }
  }
  if (m > 0 || ms > 0) c = g.sum(c);  // m, ms are s's: the same in every lane
  if (g.lane != 0) return 1;
  int count = c.count, scene = c.scene;
  vec3 sn = c.sn;  // sum of the scene contact normals
  if (S.sdf.active()) {
    // Kept for add_sdf_contact, which runs next at the same positions (the SDF costs more than the
    // rest of a fluid particle's contact work).
    SdfSample3 q = scene_sdf(S.sdf, p);
    S.sdf_at[s] = vec4{q.grad.x, q.grad.y, q.grad.z, q.d};
    if (q.d < S.c.radius) ++scene, sn += q.grad;
  }
  S.scene_n[s] = sn;
  if (scene > 0 && phase::is(S.sphase[s], phase::kRigid)) atomic_add(&S.body_contacts[phase::group(S.sphase[s])], 1);
  count += scene;
  return count > 0 ? count : 1;
}

// The two passes that project contacts: pre-stabilisation on the start positions (Macklin 2014,
// section 4.4: no friction, and no shape matching after it) and the solver iterations.
enum class ContactPass { kStabilize, kSolve };

// Weight of s's scene contacts: omega / n_s, and in the solver iterations for a rigid particle
// times (body particles / body particles touching the scene): shape matching spreads a particle's
// correction over the whole body, and without this a flat face resting on the scene would resolve
// only a fraction of its contact (and of its static friction) per iteration, so that resting
// bodies creep. Not in pre-stabilisation: no shape matching follows it there, so the factor (up to
// N for a body of N particles resting on one) would leave the body deformed by that many times its
// penetration, on x and p alike, and the next iteration's shape matching would turn the
// deformation into velocity: a cube resting on a real scan's bumps was kicked at up to 9.6 m/s.
SEAMLESS_HD inline float scene_contact_weight(const SimViews& S, int s, ContactPass pass) {
  const std::uint32_t ph = S.sphase[s];
  float self = S.c.omega / static_cast<float>(S.ncontacts[s]);
  if (pass == ContactPass::kSolve && phase::is(ph, phase::kRigid)) {
    int b = static_cast<int>(phase::group(ph));
    self *= static_cast<float>(S.body_count[b]) / static_cast<float>(max(S.body_contacts[b], 1));
  }
  return self;
}

// One lane's share of the contact corrections of s at positions P (start positions X for
// friction) with particles and scene particles; the contact sum is the lanes' sum plus add_sdf_contact. Runs
// after count_contacts at the same positions. Each pair's correction is scaled by
// omega / max(n_s, n_j): averaging as in Macklin 2014 (eq. 11) that keeps every pair's two
// corrections equal and opposite, so momentum is conserved.
SEAMLESS_HD inline vec3 contact_part(const SimViews& S, int s, const vec3* P, const vec3* X, ContactPass pass, Lanes g) {
  const bool friction = pass == ContactPass::kSolve;
  const float D = S.c.diameter, wi = S.sw[s];
  const bool fl = phase::is(S.sphase[s], phase::kFluid);
  const vec3 p = P[s], dx = p - X[s];
  const float ni = static_cast<float>(S.ncontacts[s]);
  const float mus = friction ? S.c.static_friction : 0.f, muk = friction ? S.c.kinetic_friction : 0.f;
  const float fmu = friction ? S.c.fluid_friction : 0.f;
  vec3 acc{0.f, 0.f, 0.f};
  for (int k = g.lane, m = contact_list_len(S, s); k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    std::uint32_t phj = S.sphase[j];
    if (fl && phase::is(phj, phase::kFluid)) continue;
    PairGeom pg = pair_geometry(S, s, j, P);
    if (!pg.hit) continue;
    // Fluid against a solid: solver.fluid_friction for both coefficients (0: fluids slip).
    bool any_fluid = fl || phase::is(phj, phase::kFluid);
    vec3 rel = dx - (P[j] - X[j]);
    float scale = S.c.omega / fmaxf(ni, static_cast<float>(S.ncontacts[j]));
    acc += contact_delta(pg.n, pg.depth, rel, wi, S.sw[j], any_fluid ? fmu : mus, any_fluid ? fmu : muk) * scale;
  }
  const int ms = S.nsnbr[s];
  if (ms == 0) return acc;
  const float self = scene_contact_weight(S, s, pass);
  const float smu_s = fl ? fmu : mus, smu_k = fl ? fmu : muk;
  for (int k = g.lane; k < ms; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    float l2 = length2(r);
    if (l2 >= D * D) continue;
    float l = sqrtf(l2);
    vec3 n = l > 1e-9f ? r / l : vec3{0.f, 1.f, 0.f};
    acc += contact_delta(n, D - l, dx, wi, 0.f, smu_s, smu_k) * self;
  }
  return acc;
}

// Adds the scene SDF's contact correction of s (sampled by count_contacts at the same positions)
// to acc, where the SDF touches s.
SEAMLESS_HD inline void add_sdf_contact(const SimViews& S, int s, const vec3* P, const vec3* X, ContactPass pass,
                                        vec3& acc) {
  const bool friction = pass == ContactPass::kSolve;
  if (!S.sdf.active()) return;
  const vec4 q = S.sdf_at[s];  // scene_sdf(S.sdf, p), stored by count_contacts
  if (!(q.w < S.c.radius)) return;
  const bool fl = phase::is(S.sphase[s], phase::kFluid);
  const float mu_s = !friction ? 0.f : fl ? S.c.fluid_friction : S.c.static_friction;
  const float mu_k = !friction ? 0.f : fl ? S.c.fluid_friction : S.c.kinetic_friction;
  acc += contact_delta(xyz(q), S.c.radius - q.w, P[s] - X[s], S.sw[s], 0.f, mu_s, mu_k) * scene_contact_weight(S, s, pass);
}

// Whether s has list entries that contact_part visits (otherwise its lanes need no sum).
SEAMLESS_HD inline bool has_contact_lists(const SimViews& S, int s) {
  return contact_list_len(S, s) > 0 || S.nsnbr[s] > 0;
}

}  // namespace detail

template <class Exec>
void predict(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t i) {
    vec3 v = S.v[i];
    if (S.w[i] > 0.f) v = v + S.c.gravity * S.c.dt;
    float l2 = length2(v);
    if (l2 > S.c.max_speed * S.c.max_speed) v = v * (S.c.max_speed / sqrtf(l2));
    vec3 p = S.x[i] + v * S.c.dt;
    S.v[i] = v;
    S.pred[i] = p;
    S.key[i] = S.grid.key(S.grid.cell_of(p));
    S.order[i] = static_cast<int>(i);
    if (i == 0) S.counters[4] = 0;  // largest |v|^2 of this substep, found by write_back
  });
}

template <class Exec>
void sort_cells(const Exec& ex, std::uint32_t* keys, int* values, std::int64_t n, int bits) {
  ex.sort_by_key(keys, values, n, bits);
}

template <class Exec>
std::size_t sort_cells_temp_bytes(const Exec& ex, std::int64_t n, int bits) {
  return ex.template sort_by_key_temp_bytes<std::uint32_t, int>(n, bits);
}

// Gathers the slot state into the sorted order; order[s] becomes the particle id of sorted index
// s (each thread rewrites only its own entry) and rank its inverse.
template <class Exec>
void reorder(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    const int slot = S.order[s], id = S.slot_id[slot];
    S.order[s] = id;
    S.rank[id] = static_cast<int>(s);
    S.sx[s] = S.x[slot];
    S.sp[s] = S.pred[slot];
    S.sp0[s] = S.pred[slot];
    S.sv[s] = S.v[slot];
    S.sw[s] = S.w[slot];
    S.sphase[s] = S.phase[slot];
    S.spk[s] = Packed::of_phase(S.pred[slot], S.phase[slot]);  // for find_neighbors
  });
}

template <class Exec>
void cell_starts(const Exec& ex, const std::uint32_t* keys, std::int64_t n, int* start, std::int64_t cells) {
  // Each task fills a block of cells: one binary search for the first, then a merge walk along
  // the sorted keys (work per task: the block's cells plus the entries in them). Parallel on both
  // backends, no atomics, no host sync, and no task fills a long run of empty cells alone. Blocks
  // of 32 cells on the CPU, where a thread's binary search is shared by many cells; of 4 on CUDA,
  // where the walk is a chain of dependent loads and stores: with 32, 10k particles' 2^18 cells
  // made 33 blocks of threads that each waited on 32 of them (most multiprocessors idle), with 4
  // it is 256 blocks of 4 (the binary searches' upper levels are
  // shared in cache).
  //
  // The CPU instead gives each entry i the cells (keys[i - 1], keys[i]] (entry 0 those up to
  // keys[0], entry n those after the last key) and stores i there: the cells of a task are one
  // run, which the compiler stores 4 at a time, and every cell is written once by one task. Most
  // cells are empty (2^18 cells for 10k particles), so this is ~0.3 instructions a cell instead
  // of a compare and a store (4.7 M of a 10k fluid step). Not on CUDA: one thread would fill a
  // long empty run alone. The same values either way (start[k] = number of keys below k).
  if constexpr (Exec::device == Device::CPU) {
    ex.for_each(n + 1, [=] SEAMLESS_HD(std::int64_t i) {
      const std::int64_t lo = i == 0 ? 0 : static_cast<std::int64_t>(keys[i - 1]) + 1;
      const std::int64_t hi = i == n ? cells : static_cast<std::int64_t>(keys[i]);  // inclusive
      for (std::int64_t k = lo; k <= hi; ++k) start[k] = static_cast<int>(i);
    });
    return;
  }
  constexpr std::int64_t kBlock = Exec::device == Device::CUDA ? 4 : 32;
  const std::int64_t total = cells + 1;
  ex.for_each((total + kBlock - 1) / kBlock, [=] SEAMLESS_HD(std::int64_t b) {
    const std::int64_t k0 = b * kBlock, k1 = k0 + kBlock < total ? k0 + kBlock : total;
    int pos = lower_bound_key(keys, static_cast<int>(n), static_cast<std::uint32_t>(k0));
    for (std::int64_t k = k0; k < k1; ++k) {
      while (pos < n && keys[pos] < static_cast<std::uint32_t>(k)) ++pos;
      start[k] = pos;
    }
  });
}

template <class Exec>
void cell_keys(const Exec& ex, const vec3* p, std::int64_t n, GridSpec g, std::uint32_t* keys, int* idx) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    keys[i] = g.key(g.cell_of(p[i]));
    idx[i] = static_cast<int>(i);
  });
}

template <class Exec>
void gather_vec3(const Exec& ex, const vec3* src, const int* idx, std::int64_t n, vec3* dst) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) { dst[i] = src[idx[i]]; });
}

namespace detail {
// Appends the candidates [a, e) of s that pass keep(j) to list (stride col, cap entries and a
// spare slot at cap), the lanes of g taking every g.size-th candidate and Lanes::rank placing
// them, so the list keeps the candidates' order whatever the lane count. Branch-free: about half
// the candidates fail the distance test at random, which a branch mispredicts; a rejected one is
// written to the spare slot, which nothing reads. cnt counts every accepted candidate (also past
// the cap); kept(j) is called for those stored.
template <class Keep, class Kept>
SEAMLESS_HD inline void append_run(int a, int e, Lanes g, int* list, std::int64_t col, int cap, int& cnt,
                                   Keep&& keep, Kept&& kept) {
  for (int b = a; b < e; b += g.size) {  // the same trip count in every lane of the group
    const bool in = b + g.lane < e;
    const int j = in ? b + g.lane : a;  // lanes past the run look at a valid entry, and reject it
    const bool ok = in & keep(j);
    int found = 0;
    const int slot = cnt + g.rank(ok, &found);
    const bool store = ok & (slot < cap);
    list[(store ? slot : cap) * col] = j;
    kept(j, store);
    cnt += found;
  }
}

// The CPU's candidate loop over the entries [a, e) of a run, none of them s (find_neighbors):
// every candidate is written to its slot (list row-major, col = 1 on the CPU), where the next
// one overwrites it unless it was kept: about half the candidates fail the distance test at
// random, which a branch mispredicts (the slot past the last kept entry, like the spare one at
// cap, is never read). Clamp: whether the slot must be clamped to the spare one (only where the
// run can reach the cap). General: the rigid/cloth pair test (may_interact). Everything in
// locals, so that the stores to list cannot make the compiler reload s, cap or the count.
// Returns the count.
template <bool General, bool Clamp>
SEAMLESS_HD inline int scan_candidates(const SimViews& S, vec3 p, float R2, std::uint32_t ph, int s, int a, int e, int* list,
                                       int cap, int c) {
  const Packed* const spk = S.spk;
  for (int j = a; j < e; ++j) {
    const Packed q = spk[j];  // position and phase in one load
    bool ok = length2(p - q.xyz()) < R2;
    if constexpr (General) ok = ok && may_interact(S, ph, q.bits(), s, j);
    list[Clamp ? (c < cap ? c : cap) : c] = j;
    c += ok;
  }
  return c;
}

// CUDA's candidate loop for a lane that walks its runs alone (find_neighbors): the candidates
// [a, e) of s, 4 at a time, all 4 loaded before any is tested (lanes past the run load its last
// entry and reject it): 4 loads in flight instead of one chain of load-test-store per candidate
// (see for_each_entry; 2 or 8 at a time were slower). Only kept candidates are stored: a store
// for every candidate (the CPU's branch-free way) costs memory traffic that the diverging
// threads of a warp cannot coalesce. They are stored through a pointer that moves one column per
// stored candidate: indexing the column-major list by count x column took 64-bit multiplies and
// a branch per candidate (docs/PERFORMANCE.md has the measurements).
// General: the rigid/cloth pair test (may_interact), compiled only into the walk of rigid and
// cloth particles (a runtime test per candidate left its loads if-converted into the fluid
// walk, 7 % of the instructions). cnt counts every accepted candidate, solid those stored
// without a bit of solid_mask.
template <bool General>
SEAMLESS_HD inline void scan_run_lane(const SimViews& S, vec3 p, float R2, std::uint32_t ph, int s,
                                      std::uint32_t solid_mask, int a, int e, int* list, int cap, int& cnt, int& solid) {
  const int col = static_cast<int>(S.nbr_col);  // particle count on CUDA (< 2^31)
  int c = cnt, so = solid;
  int* out = list + static_cast<std::int64_t>(c < cap ? c : cap) * col;
  for (int b = a; b < e; b += 4) {
    Packed q[4];
    SEAMLESS_PHYS_UNROLL
    for (int u = 0; u < 4; ++u) q[u] = S.spk[b + u < e ? b + u : e - 1];  // position and phase
    SEAMLESS_PHYS_UNROLL
    for (int u = 0; u < 4; ++u) {
      const int j = b + u;
      const std::uint32_t phj = q[u].bits();
      bool ok = (j < e) & (j != s) & (length2(p - q[u].xyz()) < R2);
      if constexpr (General) ok = ok && may_interact(S, ph, phj, s, j);
      const bool store = ok & (c < cap);
      so += store & ((phj & solid_mask) == 0u);
      if (store) *out = j;
      out += store ? col : 0;
      c += ok;
    }
  }
  cnt = c, solid = so;
}

// s's list lengths (cnt candidates kept, solid of them not fluid, scnt static ones) and the
// overflow counters.
SEAMLESS_HD inline void finish_neighbors(const SimViews& S, int s, int cnt, int solid, int scnt) {
  if (cnt > S.c.max_neighbors) atomic_add(&S.counters[0], 1);
  // Read first: the shared maximum rarely changes, so most particles only load it.
  if (cnt > atomic_load(&S.counters[2])) atomic_max(&S.counters[2], cnt);
  S.nnbr[s] = cnt < S.c.max_neighbors ? cnt : S.c.max_neighbors;
  S.nsolid[s] = solid;
  if (S.ns > 0) {
    if (scnt > S.c.max_static_neighbors) atomic_add(&S.counters[1], 1);
    if (scnt > atomic_load(&S.counters[3])) atomic_max(&S.counters[3], scnt);
  }
  S.nsnbr[s] = scnt < S.c.max_static_neighbors ? scnt : S.c.max_static_neighbors;
}
}  // namespace detail

template <class Exec>
void find_neighbors(const Exec& ex, const SimViews& S) {
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    // A CPU thread walks a particle's runs alone (Lanes{}); CUDA does from about 270k particles.
    // (Declared here: an extended CUDA lambda cannot capture what an if constexpr tests.)
    constexpr bool kOneLane = Exec::device == Device::CPU;
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    const float R = S.c.search_radius, R2 = R * R;
    const std::uint32_t ph = S.sphase[s];
    // Only rigid and cloth particles skip pairs (may_interact); a fluid particle counts the
    // entries that are not fluid (both_fluid), anything else every stored entry.
    const bool plain = !phase::is(ph, phase::kRigid | phase::kCloth), sfluid = phase::is(ph, phase::kFluid);
    const int cap = S.c.max_neighbors;
    int* const list = S.nbr + s * S.nbr_row;
    int cnt = 0, solid = 0;
    if constexpr (kOneLane) {
      // The CPU: the same entries in the same order as append_run with one lane, in a loop of
      // its own (counts in registers, one load per candidate, the rigid/cloth test only for
      // rigid and cloth particles, branch-free store); the non-fluid entries of a fluid
      // particle are counted afterwards over the ~30 stored entries instead of the ~70
      // candidates.
      auto walk = [&](auto general) {
        constexpr bool kGeneral = decltype(general)::value;
        for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
          // s itself sits in one run (its own row): the run is split around it instead of
          // testing j != s for every candidate. Where the run cannot reach the cap, the slot
          // needs no clamp.
          const bool self = a <= s && s < e;
          if (cnt + (e - a) <= cap) {
            if (self) cnt = detail::scan_candidates<kGeneral, false>(S, p, R2, ph, s, s + 1, e, list, cap,
                                                                     detail::scan_candidates<kGeneral, false>(S, p, R2, ph, s, a, s, list, cap, cnt));
            else cnt = detail::scan_candidates<kGeneral, false>(S, p, R2, ph, s, a, e, list, cap, cnt);
          } else {
            if (self) cnt = detail::scan_candidates<kGeneral, true>(S, p, R2, ph, s, s + 1, e, list, cap,
                                                                    detail::scan_candidates<kGeneral, true>(S, p, R2, ph, s, a, s, list, cap, cnt));
            else cnt = detail::scan_candidates<kGeneral, true>(S, p, R2, ph, s, a, e, list, cap, cnt);
          }
        });
      };
#if !defined(__CUDACC__)
      if (plain && simd::cpu_simd()) cnt = detail::scan_runs_simd(S, p, R, s, list, cap);
      else
#endif
      if (plain) walk(std::false_type{});
      else walk(std::true_type{});
      const int stored = cnt < cap ? cnt : cap;
      if (!sfluid) solid = stored;
      else
        for (int k = 0; k < stored; ++k) solid += !phase::is(S.spk[list[k * S.nbr_col]].bits(), phase::kFluid);
    } else if (g.size == 1) {  // (if constexpr ... else if: the CUDA instantiation)
      // CUDA, one lane: as above (the rigid/cloth test compiled only into the walk of rigid and
      // cloth particles), the non-fluid entries counted on the way (the phase is loaded anyway)
      // and only kept candidates stored.
      const std::uint32_t solid_mask = sfluid ? phase::kFluid : 0u;  // stored entries without these bits count
      auto walk = [&](auto general) {
        for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
          detail::scan_run_lane<decltype(general)::value>(S, p, R2, ph, s, solid_mask, a, e, list, cap, cnt, solid);
        });
      };
      if (plain) walk(std::false_type{});
      else walk(std::true_type{});
    } else {
      for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
        detail::append_run(
            a, e, g, list, S.nbr_col, cap, cnt,
            [&](int j) {
              const Packed q = S.spk[j];
              return (j != s) & (length2(p - q.xyz()) < R2) & detail::may_interact(S, ph, q.bits(), s, j);
            },
            [&](int j, bool stored) { solid += stored & !detail::both_fluid(ph, S.spk[j].bits()); });
      });
    }
    int scnt = 0;
    if (S.ns > 0) {
      for_each_run_in_radius(S.sgrid, S.scell_start, p, R, [&](int a, int e) {
        detail::append_run(
            a, e, g, S.snbr + s * S.snbr_row, S.snbr_col, S.c.max_static_neighbors, scnt,
            [&](int j) { return length2(p - S.stat[j]) < R2; },
            [](int, bool) {});
      });
    }
    solid = g.sum(solid);
    if (g.lane != 0) return;
    detail::finish_neighbors(S, s, cnt, solid, scnt);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::neighbors_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kSearchLanes, one);
}

// Macklin 2014, section 4.4: contacts that already exist at the start positions are resolved on
// x and p together, so that they are removed without adding velocity.
template <class Exec>
void stabilize(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_contacts[b] = 0; });
  ex.for_each_grouped(S.n, kPairLanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const int nc = detail::count_contacts(S, s, S.sx, g);
    if (g.lane == 0) S.ncontacts[s] = nc;
  });
  ex.for_each_grouped(S.n, kPairLanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    if (!(S.sw[s] > 0.f)) {
      if (g.lane == 0) S.tmp[s] = {0.f, 0.f, 0.f};
      return;
    }
    vec3 acc = detail::contact_part(S, s, S.sx, S.sx, detail::ContactPass::kStabilize, g);
    if (detail::has_contact_lists(S, s)) acc = g.sum(acc);
    if (g.lane != 0) return;
    detail::add_sdf_contact(S, s, S.sx, S.sx, detail::ContactPass::kStabilize, acc);
    S.tmp[s] = acc;
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    vec3 d = S.tmp[s];
    S.sx[s] += d;
    S.sp[s] += d;
    S.sp0[s] += d;
  });
}

// Density (PBF eq. 2, number density: rho_i = sum_j W_ij, solid neighbours weighted by
// solid_density_scale, Macklin 2014 section 7.1), constraint C_i = rho_i / rho_0 - 1 (eq. 1,
// clamped to C_i >= 0 when unilateral) and lambda_i = -C_i / (sum_k |grad_k C_i|^2 + eps)
// (eqs. 8-11). Only fluid particles are moved by the density constraint.
namespace detail {
// One lane's share of the density sums of fluid particle s (prepare_constraints).
struct DensitySum {
  float rho, sum2;
  vec3 gi;
};
SEAMLESS_HD inline DensitySum operator+(const DensitySum& a, const DensitySum& b) {
  return {a.rho + b.rho, a.sum2 + b.sum2, a.gi + b.gi};
}

// One pair's kernel values for r = p_i - p_j (poly6 wgt, spiky gradient gw) and grad_j C_i =
// gw / rho_0; F is float or the CPU's SIMD lanes (V their vec3).
template <class F, class V>
struct DensityPair {
  V gw, grad;
  F wgt;
};
template <class F, class V>
SEAMLESS_HD inline DensityPair<F, V> density_pair(const SphKernel& W, float inv_rho0, V r) {
  DensityPair<F, V> d;
  d.wgt = W.poly6(length2(r));
  d.gw = pair_grad(W, r);
  d.grad = d.gw * inv_rho0;
  return d;
}

// Lane g's share of rho_i (starting from W(0) in lane 0), sum_j |grad_j C_i|^2 and grad_i C_i;
// with Cache, each pair's kernel values are kept in pair_w for pbf_part.
template <bool Cache>
SEAMLESS_HD inline DensitySum density_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float inv_rho0 = 1.f / S.c.rest_density, sw = S.c.solid_density_scale;
  DensitySum d{g.lane == 0 ? S.c.W.poly6(0.f) : 0.f, 0.f, {0.f, 0.f, 0.f}};
  const bool mixed = S.nsolid[s] != 0;  // otherwise every neighbour is fluid: no phase loads
  // Local copies: the stores to pair_w (floats) could otherwise alias the kernel constants in S,
  // which the compiler would then reload for every pair.
  const SphKernel W = S.c.W;
  const int* const list = S.nbrs(s);
  Packed* const cache = S.pair_w + s * S.nbr_row;
  const std::int64_t col = S.nbr_col;
  const auto gather = [&](int j) { return S.spk[j]; };  // position and phase in one load
  for_each_entry<kPairBatch1>(list, col, S.nnbr[s], g, gather, [&](int k, const Packed& q) {
    const DensityPair<float, vec3> dp = density_pair<float>(W, inv_rho0, p - q.xyz());
    if constexpr (Cache) cache[k * col] = Packed::of(dp.gw, dp.wgt);
    // A solid neighbour's terms are scaled by sw and add nothing to sum2 (selects, not branches:
    // for_each_entry; x 1 and + 0 leave a fluid pair's sums bit for bit as they were).
    const bool fluid = !mixed || phase::is(q.bits(), phase::kFluid);
    const float f = fluid ? 1.f : sw;
    d.rho += f * dp.wgt;
    d.gi += dp.grad * f;
    d.sum2 += fluid ? length2(dp.grad) : 0.f;
  });
  for (int k = g.lane, m = S.nsnbr[s]; k < m; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    d.rho += sw * S.c.W.poly6(length2(r));
    d.gi += S.c.W.spiky_grad(r) * (sw * inv_rho0);
  }
  return d;
}

// Fluid particle s's constraint from its sums d and its contact count nc.
SEAMLESS_HD inline void finish_density(const SimViews& S, int s, int nc, const DensitySum& d) {
  S.ncontacts[s] = nc;
  float C = d.rho * (1.f / S.c.rest_density) - 1.f;
  if (S.c.unilateral && C < 0.f) C = 0.f;
  const float lambda = -C / (d.sum2 + length2(d.gi) + S.c.relaxation);
  S.lambda[s] = lambda;
  S.spl[s] = Packed::of(S.sp[s], lambda);  // what solve_contacts_fluid gathers of a neighbour
  S.density[s] = d.rho;
  S.h_rho[s] = S.c.h / d.rho;  // once here instead of once per neighbour pair in velocity_effects
}
}  // namespace detail

template <class Exec>
void prepare_constraints(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_contacts[b] = 0; });
  detail::pack_positions(ex, S);
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const int nc = detail::count_contacts(S, s, S.sp, g);
    if (!phase::is(S.sphase[s], phase::kFluid)) {
      if (g.lane != 0) return;
      S.ncontacts[s] = nc;
      S.lambda[s] = 0.f;
      S.spl[s] = Packed::of(S.sp[s], 0.f);
      S.density[s] = S.c.rest_density;
      S.h_rho[s] = S.c.h / S.c.rest_density;
      return;
    }
    const detail::DensitySum d = g.sum(detail::density_part<detail::kCachePairs<Exec>>(S, s, g));
    if (g.lane != 0) return;
    detail::finish_density(S, s, nc, d);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::density_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

namespace detail {
// Lane g's share of the contact corrections (acc) and of the PBF sum (f) of s.
struct SolveSum {
  vec3 acc, f;
};
SEAMLESS_HD inline SolveSum operator+(const SolveSum& a, const SolveSum& b) { return {a.acc + b.acc, a.f + b.f}; }

// One fluid pair's term of the PBF sum is grad times this factor, lambda_i + lambda_j + s_corr,
// s_corr from the pair's poly6 wgt (eq. 13, n = 4); F is float or the CPU's SIMD lanes.
// Without a branch: with s_corr off (scorr_k = 0), sc is -0 and li + lj + sc is li + lj to the bit.
template <class F>
SEAMLESS_HD inline F pbf_factor(const SimConstants& c, F wgt, F li, F lj) {
  const F q = wgt * c.scorr_inv_wdq;
  const F sc = -c.scorr_k * q * q * q * q;
  return li + lj + sc;
}

// The PBF position update of fluid particle s (eq. 12) with the artificial pressure s_corr
// (eq. 13, n = 4), before the division by rho_0: lane g's share. With Cached, the pairs' kernel
// values come from pair_w (prepare_constraints at these positions) instead of the positions.
// Mixed: whether s has neighbours that are not fluid (nsolid); otherwise a loop of its own without
// phase loads (a runtime test left predicated loads and byte moves in every pair; the two loops
// are faster on fluid_1m, docs/PERFORMANCE.md).
template <bool Cached, bool Mixed>
SEAMLESS_HD inline vec3 pbf_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float li = S.lambda[s], sw = S.c.solid_density_scale;
  constexpr bool mixed = Mixed;
  vec3 f{0.f, 0.f, 0.f};
  // Position and lambda in one load (Cached: lambda alone), and whether j is fluid.
  const auto gather = [&](int j) {
    const bool fluid = !mixed || phase::is(S.sphase[j], phase::kFluid);
    return Gather1{Cached ? Packed{0.f, 0.f, 0.f, S.lambda[j]} : S.spl[j], fluid};
  };
  for_each_entry<kPairBatch1>(S.nbrs(s), S.nbr_col, S.nnbr[s], g, gather, [&](int k, const Gather1& n) {
    vec3 grad;
    float wgt, lj;
    if constexpr (Cached) {
      const Packed gw = S.pair_w[s * S.nbr_row + k * S.nbr_col];
      grad = gw.xyz(), wgt = gw.w, lj = n.a.w;
    } else {
      const Packed pl = n.a;
      const vec3 r = p - pl.xyz();
      grad = pair_grad(S.c.W, r), lj = pl.w;
      wgt = S.c.W.poly6(length2(r));  // (s_corr off: unused, see pbf_factor)
    }
    f += grad * (n.fluid ? pbf_factor(S.c, wgt, li, lj) : li * sw);  // a solid neighbour: li * sw alone
  });
  for (int k = g.lane, m = S.nsnbr[s]; k < m; k += g.size) f += S.c.W.spiky_grad(p - S.stat[S.snbrs(s)[k * S.snbr_col]]) * (li * sw);
  return f;
}

// s's new position from its sums (the contacts' part.acc, the PBF or coupling sum part.f).
SEAMLESS_HD inline void finish_solve(const SimViews& S, int s, const SolveSum& part, bool fluid, bool coupled) {
  vec3 acc = part.acc;
  add_sdf_contact(S, s, S.sp, S.sx, ContactPass::kSolve, acc);
  if (fluid) acc += part.f * (1.f / S.c.rest_density);
  if (coupled) acc += part.f * (S.c.solid_density_scale / S.c.rest_density);
  S.tmp[s] = S.sp[s] + acc;
}

// Two-way coupling of solid particle s: the reaction of the density correction a fluid neighbour
// j received from it (equal and opposite momentum: scaled by w_s / w_j), lane g's share.
SEAMLESS_HD inline vec3 coupling_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float ws = S.sw[s];
  vec3 f{0.f, 0.f, 0.f};
  for (int k = g.lane, m = S.nnbr[s]; k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    if (!phase::is(S.sphase[j], phase::kFluid)) continue;
    const Packed pl = S.spl[j];
    f += S.c.W.spiky_grad(p - pl.xyz()) * (pl.w * ws / S.sw[j]);
  }
  return f;
}
}  // namespace detail

template <class Exec>
void solve_contacts_fluid(const Exec& ex, const SimViews& S) {
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    if (!(S.sw[s] > 0.f)) {
      if (g.lane == 0) S.tmp[s] = p;
      return;
    }
    const bool fluid = phase::is(S.sphase[s], phase::kFluid), coupled = !fluid && S.c.solid_density_scale > 0.f;
    detail::SolveSum part{detail::contact_part(S, s, S.sp, S.sx, detail::ContactPass::kSolve, g), {0.f, 0.f, 0.f}};
    if (fluid) {
      constexpr bool kCache = detail::kCachePairs<Exec>;
      part.f = S.nsolid[s] != 0 ? detail::pbf_part<kCache, true>(S, s, g) : detail::pbf_part<kCache, false>(S, s, g);
    }
    if (coupled) part.f = detail::coupling_part(S, s, g);
    part = g.sum(part);
    if (g.lane != 0) return;
    detail::finish_solve(S, s, part, fluid, coupled);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::solve_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

// Static friction of a rigid body as a whole (Macklin 2014, section 6.1, applied to the body):
// shape matching moves the particles touching the scene after their contacts removed their
// tangential displacement (it turns the body a little under the friction torque at its base), and
// by the next iteration their contacts are resolved, so the static-friction bound mu_s * depth of
// the particle contacts is near zero and nothing removes that slip again: a body held by static
// friction crept down an incline. Here, after shape matching, the mean tangential displacement t
// over the step of the body's touching particles (tangential to each particle's scene normal) is
// removed by moving the whole body back by t, where static friction holds: where the tangential
// displacement the prediction asked for (sp0 - x, before any correction) is below mu_s times the
// mean normal correction in the step (eq. 24's condition, for the body's contact patch). The
// contact points then stay put on average, without a torque (the body may still turn about them).
// Otherwise the particles' kinetic friction acts alone.
template <class Exec>
void body_static_friction(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nchunks, [=] SEAMLESS_HD(std::int64_t c) {
    SlipSum sum{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, 0.f, 0.f};
    for (int id = S.chunk_start[c], e = S.chunk_start[c] + S.chunk_count[c]; id < e; ++id) {
      const int s = S.rank[id];
      const vec3 sn = S.scene_n[s];
      const float l = length(sn);
      if (!(l > 0.f)) continue;
      const vec3 n = sn / l, dx = S.sp[s] - S.sx[s], free = S.sp0[s] - S.sx[s];
      sum.t += dx - n * dot(dx, n);
      sum.free += free - n * dot(free, n);
      sum.push += fmaxf(dot(n, S.sp[s] - S.sp0[s]), 0.f);
      sum.count += 1.f;
    }
    S.chunk_slip[c] = sum;
  });
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) {
    SlipSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, 0.f, 0.f};
    for (int c = S.body_chunk_start[b], e = c + S.body_chunk_count[b]; c < e; ++c) t = t + S.chunk_slip[c];
    vec3 back{0.f, 0.f, 0.f};
    if (t.count > 0.f && length(t.free) < S.c.static_friction * t.push) back = -t.t / t.count;
    S.body_shift[b] = back;
    S.body_c[b] = S.body_c[b] + back;
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    std::uint32_t ph = S.sphase[s];
    if (phase::is(ph, phase::kRigid) && S.sw[s] > 0.f) S.sp[s] += S.body_shift[phase::group(ph)];
  });
}

template <class Exec>
void shape_match(const Exec& ex, const SimViews& S) {
  if (S.nbodies == 0) return;
  // Partial sums over fixed-size chunks of each body's particles, then per-body totals: a
  // deterministic segmented reduction (no float atomics). Offsets are taken from the previous
  // centre so that sum (p - ref) q^T does not cancel catastrophically far from the origin.
  ex.for_each(S.nchunks, [=] SEAMLESS_HD(std::int64_t c) {
    vec3 ref = S.body_c[S.chunk_body[c]];
    RigidSum sum{{0.f, 0.f, 0.f}, mat3::zero()};
    for (int id = S.chunk_start[c], e = S.chunk_start[c] + S.chunk_count[c]; id < e; ++id) {
      vec3 d = S.sp[S.rank[id]] - ref;
      sum.p += d;
      sum.A = sum.A + outer(d, S.rest[id]);
    }
    S.chunk_sum[c] = sum;
  });
  // Mueller 2005: c = mean position (eq. 4.4), A_pq = sum (p - c) q^T = sum (p - ref) q^T because
  // the rest offsets q sum to zero; R = rotational part of A_pq (eq. 4.5), found on the device.
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) {
    RigidSum t{{0.f, 0.f, 0.f}, mat3::zero()};
    for (int c = S.body_chunk_start[b], e = c + S.body_chunk_count[b]; c < e; ++c) t = t + S.chunk_sum[c];
    vec3 shift = t.p / static_cast<float>(S.body_count[b]);
    vec4 q = extract_rotation(t.A, S.body_q[b], S.c.rotation_iterations);
    S.body_q[b] = q;
    S.body_R[b] = quat_to_mat(q);
    S.body_shift[b] = shift;
  });
  // Goal positions g_i = R q_i + c (eq. 4.6), approached with the body's stiffness. The
  // correction is formed relative to the reference point, so that its rounding error is relative
  // to the body's size rather than to the distance from the origin (velocities are corrections
  // divided by dt: this keeps momentum at float precision).
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    std::uint32_t ph = S.sphase[s];
    if (!phase::is(ph, phase::kRigid) || !(S.sw[s] > 0.f)) return;
    int b = static_cast<int>(phase::group(ph));
    vec3 local = S.sp[s] - S.body_c[b];
    vec3 goal = S.body_R[b] * S.rest[S.order[s]] + S.body_shift[b];
    S.sp[s] += (goal - local) * S.body_stiffness[b];
  });
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_c[b] = S.body_c[b] + S.body_shift[b]; });
  if (S.c.static_friction > 0.f) body_static_friction(ex, S);
}

// Stretch constraints (Mueller 2007, eq. 4.7/4.8), colour after colour: edges
// [colour_off[c], colour_off[c + 1]). The host colours the edges so that no particle has two edges
// of one colour: each colour is then projected fully and in place (Gauss-Seidel over colours, the
// usual graph colouring of parallel PBD) instead of averaged (Jacobi), which with 8 edges per
// particle and 2 iterations left hanging cloth stretched by 20 %. One task per edge writes both
// of its particles, which no other task of the colour touches. The colours are the phases of one
// for_each_phases sweep (one launch for a small cloth on CUDA, the same order as a launch each).
template <class Exec>
void cloth_stretch(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours) {
  // What the sweep reads, staged for it (in fast memory where the executor can, most valuable
  // first: the positions it writes, then the per-particle and per-edge constants).
  const std::int64_t ne = colour_off[colours];
  ex.for_each_phases_staged(
      colours, colour_off, colour_off + 1,
      [=] SEAMLESS_HD(int, std::int64_t e, vec3* sp, const float* sw, const int* rank, const int* ea, const int* eb,
                      const float* len, const float* stiff) {
        const int a = rank[ea[e]], b = rank[eb[e]];
        const vec3 pa = sp[a], pb = sp[b];
        const float wa = sw[a], wb = sw[b], L = len[e], k = stiff[e];
        sp[a] = pa + distance_delta(pa, pb, wa, wb, L, k);
        sp[b] = pb + distance_delta(pb, pa, wb, wa, L, k);
      },
      Staged<vec3>{S.sp, S.n}, Staged<const float>{S.sw, S.n}, Staged<const int>{S.rank, S.n},
      Staged<const int>{S.edge_a, ne}, Staged<const int>{S.edge_b, ne}, Staged<const float>{S.edge_len, ne},
      Staged<const float>{S.edge_k, ne});
}

// Strain limiting (Provot 1995, section 5): after the solver iterations, `passes` Gauss-Seidel
// sweeps over the edge colours (as in cloth_stretch, all in one for_each_phases sweep); every edge
// stretched or compressed by more than its limit (a fraction of the rest length) is brought back
// to the limit (over-relaxed by cloth_strain_omega), in place; edges within the limit are left
// alone. This pass cannot see the contacts, so a particle that touched the scene in the last
// iteration (scene_n != 0) counts as heavier (inverse mass times strain_contact_weight): the
// scene holds it, and the free part of the cloth takes more of the correction instead of the
// limiter pulling the particle into the scene (mass scaling in the spirit of Macklin 2014's
// stacking heuristic).
template <class Exec>
void cloth_strain_limit(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours, int passes) {
  std::vector<std::int64_t> begin, end;
  for (int pass = 0; pass < passes; ++pass)
    for (int c = 0; c < colours; ++c) begin.push_back(colour_off[c]), end.push_back(colour_off[c + 1]);
  // Staged as in cloth_stretch (32 phases for 4 passes over 8 colours: the most to gain).
  const std::int64_t ne = colour_off[colours];
  const float cw = S.c.strain_contact_weight, om = S.c.strain_omega;
  ex.for_each_phases_staged(
      static_cast<int>(begin.size()), begin.data(), end.data(),
      [=] SEAMLESS_HD(int, std::int64_t e, vec3* sp, const float* sw, const int* rank, const vec3* scene_n,
                      const int* ea, const int* eb, const float* len, const float* limit) {
        const float lim = limit[e];
        if (!(lim > 0.f)) return;
        const int a = rank[ea[e]], b = rank[eb[e]];
        const vec3 pa = sp[a], pb = sp[b];
        const float L = len[e];
        const float wa = sw[a] * (length2(scene_n[a]) > 0.f ? cw : 1.f);
        const float wb = sw[b] * (length2(scene_n[b]) > 0.f ? cw : 1.f);
        sp[a] = pa + strain_limit_delta(pa, pb, wa, wb, L, lim, om);
        sp[b] = pb + strain_limit_delta(pb, pa, wb, wa, L, lim, om);
      },
      Staged<vec3>{S.sp, S.n}, Staged<const float>{S.sw, S.n}, Staged<const int>{S.rank, S.n},
      Staged<const vec3>{S.scene_n, S.n}, Staged<const int>{S.edge_a, ne}, Staged<const int>{S.edge_b, ne},
      Staged<const float>{S.edge_len, ne}, Staged<const float>{S.edge_limit, ne});
}

// Bending constraints (Jacobi, averaged through their stiffness on the host): each constraint's
// four corrections once (bend_delta[4 b + vertex]), then every particle gathers its own, in the
// order of its incidence list (no float atomics), which names the slots directly (one dependent
// load less than looking the vertex up in the constraint's Quad).
template <class Exec>
void cloth_bend(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbends, [=] SEAMLESS_HD(std::int64_t b) {
    Quad q = S.bend_ids[b];
    int ids[4] = {q.a, q.b, q.c, q.d};
    vec3 pos[4];
    float w[4];
    for (int k = 0; k < 4; ++k) {
      int sk = S.rank[ids[k]];
      pos[k] = S.sp[sk];
      w[k] = S.sw[sk];
    }
    bending_deltas(pos, w, S.bend_rest[b], S.bend_k[b], S.bend_delta + 4 * b);
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t i) {
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    if (!phase::is(S.sphase[s], phase::kCloth) || !(S.sw[s] > 0.f)) {
      S.tmp[s] = p;
      return;
    }
    const int id = S.order[s];
    vec3 acc{0.f, 0.f, 0.f};
    // bend_list holds the slots 4 b + vertex of id's corrections (the host resolved the vertex).
    for (int e = S.bend_off[id], end = S.bend_off[id + 1]; e < end; ++e) acc += S.bend_delta[S.bend_list[e]];
    S.tmp[s] = p + acc;
  });
}

template <class Exec>
void update_velocity(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    // v_pred + (p - p0)/dt equals (p - x)/dt, but is exactly v_pred when no constraint acted.
    vec3 v = S.sv[s] + (S.sp[s] - S.sp0[s]) * S.c.inv_dt;
    if (S.c.sleep_threshold > 0.f && length2(v) < S.c.sleep_threshold * S.c.sleep_threshold) {
      v = {0.f, 0.f, 0.f};  // Macklin 2014, section 4.5: slow particles keep their position
      S.sp[s] = S.sx[s];
    }
    if (S.c.restitution > 0.f && S.sdf.active()) {
      // Restitution against the scene SDF: reflect the approach speed of the step's start.
      SdfSample3 q = scene_sdf(S.sdf, S.sp[s]);
      float vn0 = dot(S.sv[s], q.grad), vn = dot(v, q.grad);
      if (q.d < S.c.radius * 1.01f && vn0 < 0.f) v += q.grad * (-S.c.restitution * vn0 - vn);
    }
    S.sv[s] = v;
    // What velocity_effects' loops gather of a neighbour (the phase, needed only among solids,
    // is read from sphase there): (sp, density), the position final here, and (v, h / rho).
    S.spd[s] = Packed::of(S.sp[s], S.density[s]);
    S.svh[s] = Packed::of(v, S.h_rho[s]);
  });
}

namespace detail {

// Akinci 2013: cohesion (eq. 1) and curvature (eq. 5) accelerations, with the symmetrising
// factor K_ij = 2 rho_0 / (rho_i + rho_j) (eq. 6), and vorticity confinement (PBF eqs. 15-16),
// summed over the lanes of g (in every lane). Masses are volume fractions 1 / rho_0.
struct ForceSum {
  vec3 eta, acc;
};
SEAMLESS_HD inline ForceSum operator+(const ForceSum& a, const ForceSum& b) { return {a.eta + b.eta, a.acc + b.acc}; }

// Akinci's cohesion term of the pair r = p_i - p_j (eq. 1, before K_ij) is r times this factor
// of l = |r| (0 for coincident particles); coh_c = -cohesion / rho_0.
template <class F>
SEAMLESS_HD inline F cohesion_factor(const SphKernel& W, float coh_c, F l) {
  return select(l > 1e-9f, coh_c * W.akinci(l) / l, F(0.f));
}

// One fluid pair's terms of ForceSum: r = p_i - p_j, the pair's spiky gradient and cohesion
// factor cf, n_i, n_j, |omega_j| (wj), rho_i, rho_j; F is float or the CPU's SIMD lanes (V their
// vec3).
template <class F, class V>
SEAMLESS_HD inline void force_pair(float inv_rho0, float two_rho0, float st, V r, V grad, F cf, V ni, V nj, F wj, F rho_i,
                                   F rho_j, V& eta, V& acc) {
  eta = grad * (wj * inv_rho0);
  F K = fast_div(two_rho0, rho_i + rho_j);  // __fdividef on CUDA
  V coh = r * cf;
  V curv = (ni - nj) * st;
  acc = (coh + curv) * K;
}

// The fluid force of s from its sums t: t.acc plus vorticity confinement (PBF eqs. 15-16):
// f = eps (N x omega), N = eta / |eta|.
SEAMLESS_HD inline vec3 finish_forces(const SimViews& S, int s, ForceSum t) {
  float el = length(t.eta);
  if (el > 1e-9f && S.c.vorticity > 0.f) t.acc += cross(t.eta / el, S.vort[s]) * S.c.vorticity;
  return t.acc;
}

// The velocity of fluid particle s after viscosity (its XSPH sum in vtmp) and its forces.
SEAMLESS_HD inline vec3 fluid_velocity(const SimViews& S, int s, vec3 forces) {
  return S.sv[s] + (S.vtmp[s] * S.c.viscosity + forces * S.c.dt);
}
// cohesion_factor of |r| (r = p_i - p_j), with one reciprocal square root on CUDA (pair_grad).
template <class V>
SEAMLESS_HD inline auto pair_cohesion(const SphKernel& W, float coh_c, V r) {
#if defined(__CUDA_ARCH__)
  const float l2 = length2(r);
  if (!(l2 > 1e-18f)) return 0.f;  // l <= 1e-9, as cohesion_factor
  const float il = rsqrt_normal(l2);
  return coh_c * W.akinci(l2 * il) * il;
#else
  return cohesion_factor(W, coh_c, length(r));
#endif
}

// With Cached, each pair's spiky gradient and cohesion factor come from pair_w (vorticity_part,
// at the same positions) instead of a square root, a division and both kernels.
// Mixed: as pbf_part.
template <bool Cached, bool Mixed>
SEAMLESS_HD inline vec3 fluid_forces(const SimViews& S, int s, Lanes g) {
  const float inv_rho0 = 1.f / S.c.rest_density;
  const vec3 p = S.sp[s], ni = S.cnormal[s];
  constexpr bool mixed = Mixed;
  // Locals: nothing here is reloaded for every pair.
  const float two_rho0 = 2.f * S.c.rest_density, rho_i = S.density[s], coh_c = -S.c.cohesion * inv_rho0;
  const float st = -S.c.surface_tension;
  const int* const list = S.nbrs(s);
  const std::int64_t col = S.nbr_col, row = s * S.nbr_row;
  ForceSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}};
  // Position and density, normal and |omega| (cnv is written for fluid particles only).
  const auto gather = [&](int j) {
    const bool fluid = !mixed || phase::is(S.sphase[j], phase::kFluid);
    return Gather2{S.spd[j], fluid ? S.cnv[j] : Packed{0.f, 0.f, 0.f, 0.f}, fluid};
  };
  for_each_entry<kPairBatch2>(list, col, S.nnbr[s], g, gather, [&](int k, const Gather2& nb) {
    const bool use = nb.fluid;  // solid neighbours add nothing
    const Packed q = nb.a, nv = nb.b;
    const vec3 r = p - q.xyz();
    vec3 grad;
    float cf;
    if constexpr (Cached) {
      const Packed gw = S.pair_w[row + k * col];
      grad = gw.xyz(), cf = gw.w;
    } else {
      grad = pair_grad(S.c.W, r), cf = pair_cohesion(S.c.W, coh_c, r);
    }
    vec3 eta, acc;
    force_pair(inv_rho0, two_rho0, st, r, grad, cf, ni, nv.xyz(), nv.w, rho_i, q.w, eta, acc);
    const vec3 zero{0.f, 0.f, 0.f};
    t.eta += use ? eta : zero;
    t.acc += use ? acc : zero;
  });
  return finish_forces(S, s, g.sum(t));
}

// Keckeisen 2004 drag and lift of the triangles around cloth particle s, a third each.
SEAMLESS_HD inline vec3 cloth_aero(const SimViews& S, int s) {
  const int id = S.order[s];
  vec3 f{0.f, 0.f, 0.f};
  for (int e = S.tri_off[id], end = S.tri_off[id + 1]; e < end; ++e) {
    int3 t = S.tri_ids[S.tri_list[e]];
    int a = S.rank[t.x], b = S.rank[t.y], c = S.rank[t.z];
    vec3 vrel = (S.sv[a] + S.sv[b] + S.sv[c]) * (1.f / 3.f) - S.c.wind;
    f += triangle_aero_force(S.sp[a], S.sp[b], S.sp[c], vrel, S.c.drag, S.c.lift, S.c.air_density) * (1.f / 3.f);
  }
  return f * (S.sw[s] * S.c.dt);
}

}  // namespace detail

namespace detail {
// Lane g's share of the vorticity omega_i, the colour-field normal n_i and the XSPH sum of s.
struct VortSum {
  vec3 w, n, dv_visc;
};
SEAMLESS_HD inline VortSum operator+(const VortSum& a, const VortSum& b) {
  return {a.w + b.w, a.n + b.n, a.dv_visc + b.dv_visc};
}

// One pair's terms of VortSum for r = p_i - p_j, the velocities v_i, v_j and h / rho_j (hj), and
// (With) the pair's spiky gradient and cohesion factor for pair_w; F is float or the CPU's SIMD
// lanes (V their vec3).
template <class F, class V>
struct VortPair {
  V grad, w, n, dv;
  F cf;
};
template <bool With, class F, class V>
SEAMLESS_HD inline VortPair<F, V> vorticity_pair(const SphKernel& W, float inv_rho0, float coh_c, V r, V vi, V vj, F hj) {
  VortPair<F, V> d;
  d.grad = pair_grad(W, r);
  if constexpr (With) d.cf = pair_cohesion(W, coh_c, r);
  d.w = cross(vj - vi, -d.grad) * inv_rho0;
  d.n = d.grad * hj;
  d.dv = (vj - vi) * (W.poly6(length2(r)) * inv_rho0);
  return d;
}

// With Cache, each pair's spiky gradient and cohesion factor are kept in pair_w for
// fluid_forces, which runs next at the same positions.
// Mixed: as pbf_part.
template <bool Cache, bool Mixed>
SEAMLESS_HD inline VortSum vorticity_part(const SimViews& S, int s, Lanes g) {
  const float inv_rho0 = 1.f / S.c.rest_density;
  const vec3 p = S.sp[s], vi = S.sv[s];
  constexpr bool mixed = Mixed;
  // Locals: the stores to the caches could otherwise alias the constants in S (reloaded per pair).
  const SphKernel W = S.c.W;
  const float coh_c = -S.c.cohesion * inv_rho0;
  const int* const list = S.nbrs(s);
  const std::int64_t col = S.nbr_col, row = s * S.nbr_row;
  VortSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}};
  // Position (and density), velocity and h / rho, and whether j is fluid.
  const auto gather = [&](int j) {
    return Gather2{S.spd[j], S.svh[j], !mixed || phase::is(S.sphase[j], phase::kFluid)};
  };
  for_each_entry<kPairBatch2>(list, col, S.nnbr[s], g, gather, [&](int k, const Gather2& nb) {
    const Packed q = nb.a, vh = nb.b;
    const VortPair<float, vec3> d = vorticity_pair<Cache>(W, inv_rho0, coh_c, p - q.xyz(), vi, vh.xyz(), vh.w);
    if constexpr (Cache) S.pair_w[row + k * col] = Packed::of(d.grad, d.cf);
    const vec3 zero{0.f, 0.f, 0.f};  // solid neighbours add nothing (selects: for_each_entry)
    t.w += nb.fluid ? d.w : zero;
    t.n += nb.fluid ? d.n : zero;
    t.dv_visc += nb.fluid ? d.dv : zero;
  });
  return t;
}
}  // namespace detail

template <class Exec>
void velocity_effects(const Exec& ex, const SimViews& S, bool has_fluid) {
  if (has_fluid) {
    // Vorticity omega_i = sum_j v_ij x grad_j W_ij (PBF eq. 15), Akinci's colour-field normal
    // n_i = h sum_j (1 / rho_j) grad W_ij (Akinci 2013, eq. 4; dissertation eq. 4.21), and the
    // XSPH sum (PBF eq. 17), which needs only this pass's velocities (kept in vtmp for
    // fluid_forces: one neighbour loop fewer that gathers velocities).
    auto vort = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
      const int s = static_cast<int>(i);
      if (!phase::is(S.sphase[s], phase::kFluid)) return;
      constexpr bool kCache = detail::kCachePairs<Exec>;
      const detail::VortSum t = g.sum(S.nsolid[s] != 0 ? detail::vorticity_part<kCache, true>(S, s, g)
                                                        : detail::vorticity_part<kCache, false>(S, s, g));
      if (g.lane != 0) return;
      S.vort[s] = t.w;
      S.vort_len[s] = length(t.w);
      S.cnormal[s] = t.n;
      S.cnv[s] = Packed::of(t.n, S.vort_len[s]);  // what fluid_forces gathers of a neighbour
      S.vtmp[s] = t.dv_visc;
    };
#if !defined(__CUDACC__)
    if (!cpu_tiles(ex, S, detail::vorticity_tile, [=](int s) { vort(s, Lanes{}); }))
#endif
      ex.for_each_grouped(S.n, kPairLanes, vort, detail::kPairOccupancy);
  }
  const bool aero = S.has_cloth_constraints && (S.c.drag > 0.f || S.c.lift > 0.f);
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const std::uint32_t ph = S.sphase[s];
    const bool fluid = has_fluid && phase::is(ph, phase::kFluid);
    vec3 forces{0.f, 0.f, 0.f};
    if (fluid) {
      constexpr bool kCache = detail::kCachePairs<Exec>;
      forces = S.nsolid[s] != 0 ? detail::fluid_forces<kCache, true>(S, s, g) : detail::fluid_forces<kCache, false>(S, s, g);
    }
    if (g.lane != 0) return;  // vtmp[s] is read and written by lane 0 only
    vec3 v = S.sv[s];
    if (fluid) v = detail::fluid_velocity(S, s, forces);
    if (aero && phase::is(ph, phase::kCloth)) v += detail::cloth_aero(S, s);
    S.vtmp[s] = v;
  };
#if !defined(__CUDACC__)
  if (!has_fluid || !cpu_tiles(ex, S, detail::forces_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

// The sorted state becomes the slot state (slot s = sorted index s: coalesced, no scatter by id).
template <class Exec>
void write_back(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    S.x[s] = S.sp[s];
    S.v[s] = S.sv[s];
    S.w[s] = S.sw[s];
    S.phase[s] = S.sphase[s];
    S.slot_id[s] = S.order[s];
    // Largest |v|^2 for stats() without a reduction: the bits of non-negative floats order like
    // ints. Read first: the shared maximum rarely changes, so most particles only load it.
    const int v2 = float_bits(length2(S.sv[s]));
    if (v2 > atomic_load(&S.counters[4])) atomic_max(&S.counters[4], v2);
  });
}


// The slot state's positions and phases in id order (for what reads particles by id: the
// renderer's cloth triangles, downloads).
template <class Exec>
void slots_to_ids(const Exec& ex, const SimViews& S, vec3* x_id, std::uint32_t* phase_id) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    const int id = S.slot_id[s];
    x_id[id] = S.x[s];
    phase_id[id] = S.phase[s];
  });
}

#if !defined(__CUDACC__)
// ---- the CPU's SIMD tiles (kernels/physics/simd.hpp) ------------------------------------------
// A tile is 8 consecutive sorted particles, one per lane, each walking its own list in list
// order; the pair terms are the scalar loops' functions over simd::vf, so the sums and states are
// bit-identical to the scalar loops. A tile takes the vector path only where all 8 particles are
// fluid with fluid-only lists (the fluid's interior and surface; mixed tiles run the scalar
// loops). Compiled for AVX2 (simd::cpu_simd() checks the CPU at run time).
#if SEAMLESS_SIMD_X86
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace detail {
// The tile at s0 if it can take the vector path: its list lengths, the shortest and the longest.
struct Tile {
  int s0, m[simd::kWidth], kmin, kmax;
};
inline bool fluid_tile(const SimViews& S, int s0, Tile& t) {
  if (s0 + simd::kWidth > S.n) return false;
  t.s0 = s0, t.kmin = 1 << 30, t.kmax = 0;
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    if (!phase::is(S.sphase[s], phase::kFluid) || S.nsolid[s] != 0 || S.nsnbr[s] != 0) return false;
    t.m[l] = S.nnbr[s];
    t.kmin = t.m[l] < t.kmin ? t.m[l] : t.kmin;
    t.kmax = t.m[l] > t.kmax ? t.m[l] : t.kmax;
  }
  return true;
}

// Entry k of each lane's list (the lane's own particle where k is past its list: a valid index
// whose terms the mask drops); in: the lanes whose list has an entry k.
template <bool Masked>
SEAMLESS_SIMD_INL void tile_entries(const SimViews& S, const Tile& t, int k, int* j, simd::vm& in) {
  for (int l = 0; l < simd::kWidth; ++l) {
    const int* list = S.nbrs(t.s0 + l);
    if constexpr (Masked) {
      const bool has = k < t.m[l];
      j[l] = has ? list[k * S.nbr_col] : t.s0 + l;
      in.v[l] = has ? -1 : 0;
    } else {
      j[l] = list[k * S.nbr_col];
    }
  }
}

// Gathers of entries j of a packed array: (xyz, w) of each lane.
SEAMLESS_SIMD_INL void gather_packed(const Packed* a, const int* j, simd::v3& xyz, simd::vf& w) {
  const void* e[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) e[l] = a + j[l];
  simd::load_transpose(e, xyz.x, xyz.y, xyz.z, w);
}

// acc += d where the lanes are in (all of them unless Masked).
template <bool Masked>
SEAMLESS_SIMD_INL void tile_add(simd::v3& acc, const simd::v3& d, simd::vm in) {
  if constexpr (Masked) acc = select(in, acc + d, acc);
  else acc += d;
}

// vorticity_part of the tile's 8 particles (velocity_effects). False where the tile needs the
// scalar loops. The tiles keep nothing in pair_w: forces_tile recomputes the pairs' kernel values
// (on 8 lanes that costs less time than storing and reloading them, docs/PERFORMANCE.md; the
// scalar loops of tiles that decline keep using pair_w, and a tile
// declines in both passes or in neither).
bool vorticity_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  const float inv_rho0 = 1.f / S.c.rest_density, coh_c = -S.c.cohesion * inv_rho0;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0), vi = simd::load_v3(S.sv + s0);
  v3 tw{}, tn{}, tdv{};
  auto step = [&](int k, auto masked) {
    constexpr bool kMasked = decltype(masked)::value;
    int j[simd::kWidth];
    simd::vm in;
    tile_entries<kMasked>(S, t, k, j, in);
    v3 q, vj;
    simd::vf rho, hj;
    gather_packed(S.spd, j, q, rho);
    gather_packed(S.svh, j, vj, hj);
    const auto d = vorticity_pair<false>(W, inv_rho0, coh_c, p - q, vi, vj, hj);
    tile_add<kMasked>(tw, d.w, in);
    tile_add<kMasked>(tn, d.n, in);
    tile_add<kMasked>(tdv, d.dv, in);
  };
  for (int k = 0; k < t.kmin; ++k) step(k, std::false_type{});
  for (int k = t.kmin; k < t.kmax; ++k) step(k, std::true_type{});
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    S.vort[s] = simd::lane(tw, l);
    S.vort_len[s] = length(S.vort[s]);
    S.cnormal[s] = simd::lane(tn, l);
    S.cnv[s] = Packed::of(S.cnormal[s], S.vort_len[s]);
    S.vtmp[s] = simd::lane(tdv, l);
  }
  return true;
}

// prepare_constraints of the tile's 8 fluid particles: count_contacts lane by lane (no lists:
// the tile's lists hold fluid only, its SDF sample), density_part 8 lanes at once (nothing kept
// in pair_w: solve_tile recomputes it, see vorticity_tile), then finish_density.
bool density_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  int nc[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) nc[l] = count_contacts(S, s0 + l, S.sp, Lanes{});
  const float inv_rho0 = 1.f / S.c.rest_density;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0);
  vf rho(W.poly6(0.f)), sum2(0.f);
  v3 gi{};
  auto step = [&](int k, auto masked) {
    constexpr bool kMasked = decltype(masked)::value;
    int j[simd::kWidth];
    simd::vm in;
    tile_entries<kMasked>(S, t, k, j, in);
    v3 q;
    vf ph;
    gather_packed(S.spk, j, q, ph);
    const auto d = density_pair<vf>(W, inv_rho0, p - q);
    if constexpr (kMasked) {
      rho = select(in, rho + d.wgt, rho);
      sum2 = select(in, sum2 + length2(d.grad), sum2);
    } else {
      rho = rho + d.wgt;
      sum2 = sum2 + length2(d.grad);
    }
    tile_add<kMasked>(gi, d.grad, in);
  };
  for (int k = 0; k < t.kmin; ++k) step(k, std::false_type{});
  for (int k = t.kmin; k < t.kmax; ++k) step(k, std::true_type{});
  for (int l = 0; l < simd::kWidth; ++l) finish_density(S, s0 + l, nc[l], DensitySum{rho[l], sum2[l], simd::lane(gi, l)});
  return true;
}

// solve_contacts_fluid of the tile's 8 fluid particles: pbf_part 8 lanes at once, the pairs'
// kernel values from the positions (density_tile kept none), the contact part lane by lane
// (without solid or static neighbours only the scene SDF's contact). Takes the tiles that
// density_tile takes (particles that do not move keep their position here, as in the scalar loop).
bool solve_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0);
  vf li;
  for (int l = 0; l < simd::kWidth; ++l) li.v[l] = S.lambda[s0 + l];
  v3 f{};
  auto step = [&](int k, auto masked) {
    constexpr bool kMasked = decltype(masked)::value;
    int j[simd::kWidth];
    simd::vm in;
    tile_entries<kMasked>(S, t, k, j, in);
    v3 q;
    vf lj;
    gather_packed(S.spl, j, q, lj);
    const v3 r = p - q;
    const v3 grad = pair_grad(W, r);
    const vf wgt = W.poly6(length2(r));  // (s_corr off: unused, see pbf_factor)
    tile_add<kMasked>(f, grad * pbf_factor(S.c, wgt, li, lj), in);
  };
  for (int k = 0; k < t.kmin; ++k) step(k, std::false_type{});
  for (int k = t.kmin; k < t.kmax; ++k) step(k, std::true_type{});
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    if (!(S.sw[s] > 0.f)) S.tmp[s] = S.sp[s];
    else finish_solve(S, s, SolveSum{contact_part(S, s, S.sp, S.sx, ContactPass::kSolve, Lanes{}), simd::lane(f, l)}, true, false);
  }
  return true;
}

// velocity_effects' second pass for the tile's 8 fluid particles: fluid_forces 8 lanes at once,
// the pairs' kernel values from the positions (vorticity_tile kept none).
bool forces_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  const float inv_rho0 = 1.f / S.c.rest_density, two_rho0 = 2.f * S.c.rest_density;
  const float coh_c = -S.c.cohesion * inv_rho0, st = -S.c.surface_tension;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0), ni = simd::load_v3(S.cnormal + s0);
  vf rho_i;
  for (int l = 0; l < simd::kWidth; ++l) rho_i.v[l] = S.density[s0 + l];
  v3 eta{}, acc{};
  auto step = [&](int k, auto masked) {
    constexpr bool kMasked = decltype(masked)::value;
    int j[simd::kWidth];
    simd::vm in;
    tile_entries<kMasked>(S, t, k, j, in);
    v3 q, nj;
    vf rho_j, wj;
    gather_packed(S.spd, j, q, rho_j);
    gather_packed(S.cnv, j, nj, wj);
    const v3 r = p - q;
    const v3 grad = pair_grad(W, r);
    const vf cf = pair_cohesion(W, coh_c, r);
    v3 e, a;
    force_pair(inv_rho0, two_rho0, st, r, grad, cf, ni, nj, wj, rho_i, rho_j, e, a);
    tile_add<kMasked>(eta, e, in);
    tile_add<kMasked>(acc, a, in);
  };
  for (int k = 0; k < t.kmin; ++k) step(k, std::false_type{});
  for (int k = t.kmin; k < t.kmax; ++k) step(k, std::true_type{});
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    S.vtmp[s] = fluid_velocity(S, s, finish_forces(S, s, ForceSum{simd::lane(eta, l), simd::lane(acc, l)}));
  }
  return true;
}

// The entries of the runs [run[2 r], run[2 r + 1]) of s, in order, 8 at a time (runs joined in
// a buffer): the distance test of scan_candidates on 8 lanes (s itself rejected), then the kept
// ones left-packed and stored at slot cnt (simd::kPack), or where the 8 could reach the cap each
// candidate stored at slot min(cnt, cap) and counted where it passed (scan_candidates'
// branch-free store). Returns the count.
int scan_candidates_simd(const SimViews& S, vec3 p, float R2, int s, const int* run, int nruns, int* list, int cap) {
  constexpr int kBuf = 128;
  int buf[kBuf + 2 * simd::kWidth];
  const simd::v3 pv = simd::broadcast(p);
  simd::i8 self{}, iota{0, 1, 2, 3, 4, 5, 6, 7};
  self += s;
  int cnt = 0;
  // Tests the first nb (a multiple of kWidth) entries of buf.
  auto test = [&](int nb) {
    for (int b = 0; b < nb; b += simd::kWidth) {
      const int* j = buf + b;
      simd::i8 jv;
      std::memcpy(&jv, j, sizeof jv);
      simd::v3 q;
      simd::vf w;
      gather_packed(S.spk, j, q, w);
      const simd::vm ok = (length2(pv - q) < simd::vf(R2)) & simd::vm{jv != self};
      const int m = simd::bits(ok);
      if (cnt + simd::kWidth <= cap) {
        const simd::i8 kept = simd::permute(jv, simd::pack_lanes(m));
        std::memcpy(list + cnt, &kept, sizeof kept);
        cnt += simd::kPack.count[m];
      } else {
        for (int l = 0; l < simd::kWidth; ++l) {
          list[cnt < cap ? cnt : cap] = j[l];
          cnt += m >> l & 1;
        }
      }
    }
  };
  int nb = 0;
  for (int r = 0; r < nruns; ++r) {
    for (int a = run[2 * r], e = run[2 * r + 1]; a < e;) {
      const int take = e - a < kBuf - nb ? e - a : kBuf - nb;
      simd::i8 v = iota + a;
      for (int k = 0; k < take; k += simd::kWidth, v += simd::kWidth) std::memcpy(buf + nb + k, &v, sizeof v);
      nb += take, a += take;
      if (nb >= kBuf - simd::kWidth) {  // test the full groups, keep the rest
        const int full = nb & ~(simd::kWidth - 1);
        test(full);
        for (int k = full; k < nb; ++k) buf[k - full] = buf[k];
        nb -= full;
      }
    }
  }
  for (int l = 0; l < simd::kWidth; ++l) buf[nb + l] = s;  // padding: rejected as s itself
  test((nb + simd::kWidth - 1) & ~(simd::kWidth - 1));
  return cnt;
}

// find_neighbors' candidates of a particle s at p without the rigid/cloth test on the CPU's SIMD
// lanes: the runs of for_each_run_in_radius (the same rows, row_cells on 8 rows at once, then the
// runs in its order), then their entries 8 at a time (scan_candidates_simd); the same list as
// scan_candidates. Returns the count.
int scan_runs_simd(const SimViews& S, vec3 p, float R, int s, int* list, int cap) {
  constexpr int kReach = GridSpec::reach, kW = 2 * kReach + 1, kRows = kW * kW;
  constexpr int kVecs = (kRows + simd::kWidth - 1) / simd::kWidth;
  const GridSpec& g = S.grid;
  const int3 c = g.cell_of(p);
  const float R2 = R * R, pad = 1e-3f * g.cell;
  const std::uint32_t m = (1u << g.bits) - 1u;
  float ey2[kW], ez2[kW];
  for (int d = 0; d < kW; ++d) {
    const float ey = slab_gap(p.y, c.y + d - kReach, g.cell, pad), ez = slab_gap(p.z, c.z + d - kReach, g.cell, pad);
    ey2[d] = ey * ey, ez2[d] = ez * ez;
  }
  // Row r = dz kW + dy; lanes past the rows get R2 (no row).
  alignas(32) float d2[kVecs * simd::kWidth];
  for (int r = 0; r < kVecs * simd::kWidth; ++r) d2[r] = r < kRows ? ey2[r % kW] + ez2[r / kW] : R2;
  alignas(32) int lo[kVecs * simd::kWidth], hi[kVecs * simd::kWidth];
  for (int v = 0; v < kVecs; ++v) {
    simd::vf dv;
    std::memcpy(&dv.v, d2 + v * simd::kWidth, sizeof dv.v);
    simd::vi a, b;
    row_cells(g, simd::vf(p.x), simd::vi(c.x), R2, pad, dv, a, b);
    std::memcpy(lo + v * simd::kWidth, &a.v, sizeof a.v);
    std::memcpy(hi + v * simd::kWidth, &b.v, sizeof b.v);
  }
  int run[4 * kRows];
  int nr = 0;
  const int* start = S.cell_start;
  for (int dz = 0; dz < kW; ++dz) {
    const std::uint32_t slab = (static_cast<std::uint32_t>(c.z + dz - kReach) & m) << (2 * g.bits);
    for (int dy = 0; dy < kW; ++dy) {
      const int r = dz * kW + dy;
      if (d2[r] >= R2) continue;
      const std::uint32_t row = ((static_cast<std::uint32_t>(c.y + dy - kReach) & m) << g.bits) | slab;
      const std::uint32_t x0 = static_cast<std::uint32_t>(lo[r]) & m, x1 = static_cast<std::uint32_t>(hi[r]) & m;
      if (x0 <= x1) {
        run[nr] = start[row | x0], run[nr + 1] = start[(row | x1) + 1];
        nr += 2;
      } else {  // the x range wraps: [x0, m] and [0, x1]
        run[nr] = start[row | x0], run[nr + 1] = start[(row | m) + 1];
        run[nr + 2] = start[row], run[nr + 3] = start[(row | x1) + 1];
        nr += 4;
      }
    }
  }
  return scan_candidates_simd(S, p, R2, s, run, nr / 2, list, cap);
}

// find_neighbors of the tile's 8 particles, one per lane, where none of them needs the
// rigid/cloth test, the scene has no static particles, and all 8 share their cell's y and z
// (consecutive sorted particles along a row of cells) within a few cells along x: the rows of
// cells (for_each_run_in_radius) once for the tile, each row's x range the union of the lanes'
// ranges, and each candidate tested against the 8 particles at once. The union holds every
// lane's own candidates in its own order (the same rows in the same order, x ascending within a
// row, wrapping at the same place: the union spans fewer cells than the grid) and only
// candidates that fail its distance test besides (outside a lane's padded rows and ranges), so
// each lane's list is the one scan_candidates makes. Then each lane's kept candidates are
// left-packed into its list (simd::kPack) and find_neighbors' epilogue runs.
bool neighbors_tile(const SimViews& S, int s0) {
  constexpr int kReach = GridSpec::reach, kW = 2 * kReach + 1, kSpan = 8, kBlock = 256;
  if (s0 + simd::kWidth > S.n || S.ns > 0 || S.nbr_col != 1) return false;  // (the CPU's lists are rows)
  for (int l = 0; l < simd::kWidth; ++l)
    if (phase::is(S.sphase[s0 + l], phase::kRigid | phase::kCloth)) return false;
  using simd::vf;
  using simd::vi;
  const GridSpec& g = S.grid;
  const float R = S.c.search_radius, R2 = R * R, pad = 1e-3f * g.cell;
  const simd::v3 p = simd::load_v3(S.sp + s0);
  const vi cx = floor_int(p.x * g.inv_cell), cy = floor_int(p.y * g.inv_cell), cz = floor_int(p.z * g.inv_cell);
  int xmin = cx[0], xmax = cx[0];
  for (int l = 0; l < simd::kWidth; ++l) {
    if (cy[l] != cy[0] || cz[l] != cz[0]) return false;
    xmin = cx[l] < xmin ? cx[l] : xmin, xmax = cx[l] > xmax ? cx[l] : xmax;
  }
  if (xmax - xmin > kSpan) return false;
  const int m = (1 << g.bits) - 1;
  vf ey2[kW], ez2[kW];
  for (int d = 0; d < kW; ++d) {
    const vf ey = slab_gap(p.y, cy[0] + d - kReach, g.cell, pad), ez = slab_gap(p.z, cz[0] + d - kReach, g.cell, pad);
    ey2[d] = ey * ey, ez2[d] = ez * ez;
  }
  // The runs of the rows' unions, in for_each_run_in_radius' order.
  int ra[2 * kW * kW], re[2 * kW * kW], nr = 0;
  for (int dz = 0; dz < kW; ++dz) {
    const int slab = ((cz[0] + dz - kReach) & m) << (2 * g.bits);
    for (int dy = 0; dy < kW; ++dy) {
      const vf d2 = ey2[dy] + ez2[dz];
      const simd::vm in = d2 < vf(R2);
      const int rows = simd::bits(in);
      if (rows == 0) continue;
      vi lo, hi;
      row_cells(g, p.x, cx, R2, pad, d2, lo, hi);
      int u0 = 1 << 30, u1 = -(1 << 30);
      for (int l = 0; l < simd::kWidth; ++l) {
        if (!(rows >> l & 1)) continue;
        u0 = lo[l] < u0 ? lo[l] : u0, u1 = hi[l] > u1 ? hi[l] : u1;
      }
      const int row = (((cy[0] + dy - kReach) & m) << g.bits) | slab;
      const int x0 = u0 & m, x1 = u1 & m;
      if (x0 <= x1) {
        ra[nr] = S.cell_start[row | x0], re[nr++] = S.cell_start[(row | x1) + 1];
      } else {  // the x range wraps: [x0, m] and [0, x1]
        ra[nr] = S.cell_start[row | x0], re[nr++] = S.cell_start[(row | m) + 1];
        ra[nr] = S.cell_start[row], re[nr++] = S.cell_start[(row | x1) + 1];
      }
    }
  }
  // Candidates in blocks: each one's lane mask (bit l: kept by lane l), then the lanes' lists.
  alignas(32) int cand[kBlock + 32];
  alignas(32) std::uint8_t keep[kBlock + 32];
  int* list[simd::kWidth];
  int cnt[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) list[l] = S.nbr + (s0 + l) * S.nbr_row, cnt[l] = 0;
  const int cap = S.c.max_neighbors;
  int nc = 0;
  auto flush = [&]() {
    for (int k = nc; k < nc + 32; ++k) cand[k] = 0, keep[k] = 0;
    for (int l = 0; l < simd::kWidth; ++l) {
      int c = cnt[l];
      for (int k = 0; k < nc; k += 32) {
        const unsigned b32 = simd::byte_bits(keep + k, l);
        for (int q = 0; q < 32 && k + q < nc; q += simd::kWidth) {
          const int b = static_cast<int>(b32 >> q & 0xFFu);
          if (c + simd::kWidth <= cap) {
            simd::i8 j;
            std::memcpy(&j, cand + k + q, sizeof j);
            const simd::i8 kept = simd::permute(j, simd::pack_lanes(b));
            std::memcpy(list[l] + c, &kept, sizeof kept);
            c += simd::kPack.count[b];
          } else {
            for (int i = 0; i < simd::kWidth; ++i) {
              list[l][c < cap ? c : cap] = cand[k + q + i];
              c += b >> i & 1;
            }
          }
        }
      }
      cnt[l] = c;
    }
    nc = 0;
  };
  const Packed* const spk = S.spk;
  std::uint32_t all = ~0u;  // the phase bits that every candidate has
  for (int r = 0; r < nr; ++r) {
    for (int j = ra[r], e = re[r]; j < e; ++j) {
      const Packed q = spk[j];
      all &= q.bits();
      const simd::v3 d = p - simd::broadcast(q.xyz());
      const unsigned own = static_cast<unsigned>(j - s0);  // a lane's own particle: not kept
      const unsigned b = static_cast<unsigned>(simd::bits(length2(d) < vf(R2))) & (own < 8u ? ~(1u << own) : ~0u);
      cand[nc] = j, keep[nc] = static_cast<std::uint8_t>(b);
      if (++nc == kBlock) flush();
    }
  }
  flush();
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l, stored = cnt[l] < cap ? cnt[l] : cap;
    int solid = stored;
    if (phase::is(S.sphase[s], phase::kFluid)) {
      solid = 0;
      if (!phase::is(all, phase::kFluid))  // (otherwise every candidate is fluid)
        for (int k = 0; k < stored; ++k) solid += !phase::is(spk[list[l][k]].bits(), phase::kFluid);
    }
    finish_neighbors(S, s, cnt[l], solid, 0);
  }
  return true;
}
}  // namespace detail
#if SEAMLESS_SIMD_X86
#pragma GCC pop_options
#endif

#endif

}  // namespace seamless::kernels
