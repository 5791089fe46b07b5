// Kernels that exercise the grouped executor collectives (for_each_grouped with Lanes::sum and
// Lanes::rank, for_each_phases), instantiated for both backends (lanes_probe_cpu.cpp,
// lanes_probe_cuda.cu) so that one test checks both.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/hd.hpp"

namespace seamless::probe {

// A float and an int summed together: Lanes::sum of a struct, word by word.
struct SumCount {
  float sum = 0.f;
  int count = 0;
  SEAMLESS_HD SumCount operator+(const SumCount& o) const { return {sum + o.sum, count + o.count}; }
};

template <Executor Exec> struct LanesProbe {
  // out[i] = sum and number of vals[i * cap + k], k < counts[i] (lanes split k).
  static void grouped_sums(const Exec& ex, const int* counts, const float* vals, std::int64_t n, int cap, int max_lanes,
                           SumCount* out);

  // kept[i * cap + ...] = the k < counts[i] with odd vals[i * cap + k], in increasing k (Lanes::rank);
  // nkept[i] = how many.
  static void grouped_compact(const Exec& ex, const int* counts, const float* vals, std::int64_t n, int cap,
                              int max_lanes, int* kept, int* nkept);

  // A chain of phases over two arrays: phase p sets dst[i] = src[i] + 3 src[(i + 1) % m] for i in
  // [begin[p], end[p]) and copies the rest (dst, src = b, a for even p, a, b for odd p), so every
  // phase depends on all of the previous one's writes.
  static void phase_chain(const Exec& ex, std::uint32_t* a, std::uint32_t* b, std::int64_t m, int phases,
                          const std::int64_t* begin, const std::int64_t* end);
};

}  // namespace seamless::probe
