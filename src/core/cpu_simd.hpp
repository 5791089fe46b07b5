// Whether the CPU runs its SIMD lanes (core/simd.hpp: the particle solver's tiles, the voxel
// hash's fusion rows): AVX2 on x86-64 (checked once), always elsewhere (generic vectors).
// set_cpu_simd(false) forces the scalar loops, which give bit-identical results (tests compare
// both). Host code only.
#pragma once
#include <atomic>

// The AVX2 tiles are compiled under `#pragma GCC target`, which Clang does not honour: Clang (the
// fuzzing build, tests/fuzz) gets the generic vectors of the other targets.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SEAMLESS_SIMD_X86 1
#else
#define SEAMLESS_SIMD_X86 0
#endif

// A region of functions on the lanes, compiled for AVX2 on x86-64 (taken where cpu_simd() finds
// it at run time) and for the baseline elsewhere: SEAMLESS_SIMD_TARGET_BEGIN before them,
// SEAMLESS_SIMD_TARGET_END after.
#if SEAMLESS_SIMD_X86
#define SEAMLESS_SIMD_TARGET_BEGIN _Pragma("GCC push_options") _Pragma("GCC target(\"avx2\")")
#define SEAMLESS_SIMD_TARGET_END _Pragma("GCC pop_options")
#else
#define SEAMLESS_SIMD_TARGET_BEGIN
#define SEAMLESS_SIMD_TARGET_END
#endif

namespace seamless::simd {

inline std::atomic<int>& cpu_simd_flag() {
  static std::atomic<int> flag{-1};
  return flag;
}
inline bool cpu_simd() {
  int f = cpu_simd_flag().load(std::memory_order_relaxed);
  if (f < 0) {
#if SEAMLESS_SIMD_X86
    f = __builtin_cpu_supports("avx2") ? 1 : 0;
#else
    f = 1;
#endif
    cpu_simd_flag().store(f, std::memory_order_relaxed);
  }
  return f != 0;
}
inline void set_cpu_simd(bool on) {
  cpu_simd_flag().store(-1);
  if (!on) cpu_simd_flag().store(0);
}

}  // namespace seamless::simd
