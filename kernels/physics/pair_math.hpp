// Inline helpers shared by the physics kernel families (their .inl files only): the pair loops'
// driver (for_each_entry) and batching, the SPH pair math of the fluid passes, the packed position
// copy and the rule for which pairs are listed at all. Compiled once per backend with the family
// that includes it.
#pragma once
#include <type_traits>
#include <vector>

#include "core/atomics.hpp"
#include "core/exec.hpp"
#include "core/simd.hpp"
#include "kernels/physics/constraints.hpp"
#include "kernels/physics/solver.hpp"

// Full unrolling of a loop over a register array (CUDA; GCC would warn on the pragma).
#if defined(__CUDA_ARCH__)
#define SEAMLESS_PHYS_UNROLL _Pragma("unroll")
#else
#define SEAMLESS_PHYS_UNROLL
#endif

namespace seamless::kernels {

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
template <class Exec> inline constexpr bool kCachePairs = Exec::device == Device::CPU;

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
template <class V> SEAMLESS_HD inline V pair_grad(const SphKernel& W, V r) {
#if defined(__CUDA_ARCH__)
  const float l2 = length2(r);
  if (l2 >= W.h2 || l2 <= 1e-24f) return {0.f, 0.f, 0.f};  // l >= h or l <= 1e-12, as spiky_grad
  const float il = rsqrt_normal(l2), t = W.h - l2 * il;
  return r * (W.spiky_c * t * t * il);
#else
  return W.spiky_grad(r);
#endif
}
template <class F> SEAMLESS_HD inline F fast_div(float a, F b) {
#if defined(__CUDA_ARCH__)
  return __fdividef(a, b);
#else
  return a / b;
#endif
}

// spk = (sp, phase bits): the packed copy that the next neighbour loops gather (Packed).
template <class Exec> void pack_positions(const Exec& ex, const SimViews& S) {
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

}  // namespace detail

}  // namespace seamless::kernels
