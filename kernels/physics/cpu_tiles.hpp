// The CPU's SIMD tiles of the physics passes (defined in cpu_tiles.cpp, compiled for AVX2 where
// simd::cpu_simd() finds it at run time), and cpu_tiles(), which the families' passes call to
// run them. Never seen by nvcc.
#pragma once
#include "core/exec.hpp"
#include "core/simd.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

#if !defined(__CUDACC__)
// The CPU's SIMD tiles (defined at the end of this file).
SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {
bool vorticity_tile(const SimViews& S, int s0);
bool density_tile(const SimViews& S, int s0);
bool solve_tile(const SimViews& S, int s0);
bool forces_tile(const SimViews& S, int s0);
int scan_candidates_simd(const SimViews& S, vec3 p, float R2, int s, const int* run, int nruns, int* list, int cap);
int scan_runs_simd(const SimViews& S, vec3 p, float R, int s, int* list, int cap);
bool neighbors_tile(const SimViews& S, int s0);
}  // namespace detail
SEAMLESS_SIMD_TARGET_END

// Runs tile(S, s0) for the tiles of 8 particles and one(s) for the particles of tiles it
// declines, on the CPU when the SIMD lanes are available; false otherwise (the caller then runs
// its loop). Each tile is taken by the task of its first particle (for_each's threshold and
// schedule stay those of the particles).
template <class Exec, class Tile, class One> bool cpu_tiles(const Exec& ex, const SimViews& S, Tile tile, One one) {
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

}  // namespace seamless::kernels
