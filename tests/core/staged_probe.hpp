// A kernel for Exec::for_each_phases_staged (core/exec.hpp), instantiated for both backends
// (staged_probe_cpu.cpp, staged_probe_cuda.cu) so that one test checks both.
#pragma once
#include <cstdint>

#include "core/exec.hpp"

namespace seamless::probe {

template <Executor Exec> struct StagedProbe {
  // Red-black Gauss-Seidel on a ring of m floats x (m even), phase after phase: phase p relaxes
  // the elements i = 2 j + p % 2, j in [begin[p], end[p]) (j < m / 2), toward the mean of their
  // two neighbours, which are of the other parity (so one phase's writes never race):
  //   x[i] += w[i] * pad[i % pad_n] * (0.5 (x[i - 1] + x[i + 1]) - x[i]),   visits[i] += 1.
  // pad (all ones in the test) is listed first among the staged arrays, so that a pad too large for
  // shared memory makes the executor skip it and stage the others. staged = false runs the same
  // arithmetic through for_each_phases, with every array in place.
  static void relax_ring(const Exec& ex, float* x, int* visits, const float* w, const float* pad, std::int64_t pad_n,
                         std::int64_t m, int phases, const std::int64_t* begin, const std::int64_t* end, bool staged);
};

}  // namespace seamless::probe
