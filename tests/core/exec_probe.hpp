// A small kernel family that exercises every executor primitive, instantiated for both backends
// (exec_probe_cpu.cpp, exec_probe_cuda.cu) so the same test checks both.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::probe {

// 3 floats and a count, summed by transform_reduce: checks reductions of a struct type.
struct Moments {
  double sum = 0, sum_sq = 0;
  std::int64_t count = 0;
  SEAMLESS_HD Moments operator+(const Moments& o) const { return {sum + o.sum, sum_sq + o.sum_sq, count + o.count}; }
};

// transform_reduce_rounds: each round sums in[i] x scale into out->sum, then doubles the scale
// and logs the round's sum; the rounds stop after `rounds` or once a sum exceeds stop_above.
// The per-element terms are floats (the rounds sum float components), 40 of them so that the
// term spans more than one warp's 32 lanes; term k is in[i] x scale x (k + 1).
struct RoundTerms {
  float v[40];
  SEAMLESS_HD RoundTerms operator+(const RoundTerms& o) const {
    RoundTerms s;
    for (int k = 0; k < 40; ++k) s.v[k] = v[k] + o.v[k];
    return s;
  }
};
struct RoundSums {
  double v[40] = {};
  SEAMLESS_HD RoundSums operator+(const RoundTerms& o) const {
    RoundSums s;
    for (int k = 0; k < 40; ++k) s.v[k] = v[k] + o.v[k];
    return s;
  }
  SEAMLESS_HD RoundSums operator+(const RoundSums& o) const {
    RoundSums s;
    for (int k = 0; k < 40; ++k) s.v[k] = v[k] + o.v[k];
    return s;
  }
};
struct RoundsLog {
  double scale = 1;
  int rounds_run = 0;
  double sums[16][40] = {};
};
template <Executor Exec> struct ExecProbe {
  static void square(const Exec& ex, View<const float> in, View<float> out);

  static Moments moments(const Exec& ex, View<const float> in);

  // The same sum left on the device in *out (transform_reduce_into).
  static void moments_into(const Exec& ex, View<const float> in, Moments* out);

  static void doubling_rounds(const Exec& ex, View<const float> in, int rounds, double stop_above, RoundSums* out,
                              RoundsLog* log);

  static std::uint32_t scan(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> out);

  static void sort(const Exec& ex, View<std::uint32_t> keys, View<std::int32_t> values, int bits);

  // Histogram with atomics: counts[v % bins]++ for every v.
  static void histogram(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> counts);

  static void atomic_float_sum(const Exec& ex, View<const float> in, float* total);
};

}  // namespace seamless::probe
