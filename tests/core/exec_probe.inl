#include "core/atomics.hpp"
#include "exec_probe.hpp"

namespace seamless::probe {

template <Executor Exec>
void ExecProbe<Exec>::square(const Exec& ex, View<const float> in, View<float> out) {
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { out[i] = in[i] * in[i]; });
}

template <Executor Exec>
Moments ExecProbe<Exec>::moments(const Exec& ex, View<const float> in) {
  return ex.transform_reduce(in.size, Moments{}, [=] SEAMLESS_HD(std::int64_t i) {
    double v = in[i];
    return Moments{v, v * v, 1};
  });
}

template <Executor Exec>
void ExecProbe<Exec>::moments_into(const Exec& ex, View<const float> in, Moments* out) {
  ex.transform_reduce_into(in.size, [=] SEAMLESS_HD(std::int64_t i) {
    double v = in[i];
    return Moments{v, v * v, 1};
  }, out);
}

template <Executor Exec>
void ExecProbe<Exec>::doubling_rounds(const Exec& ex, View<const float> in, int rounds, double stop_above, RoundSums* out,
                     RoundsLog* log) {
  ex.transform_reduce_rounds(
      in.size, rounds,
      [=] SEAMLESS_HD(std::int64_t i) {
        const float v = in[i] * static_cast<float>(log->scale);  // the scale the previous round's `then` left
        RoundTerms t;
        for (int k = 0; k < 40; ++k) t.v[k] = v * static_cast<float>(k + 1);
        return t;
      },
      out, [=] SEAMLESS_HD(int r, const RoundSums& sum) {
        for (int k = 0; k < 40; ++k) log->sums[r][k] = sum.v[k];
        log->rounds_run = r + 1;
        log->scale *= 2;
        return sum.v[0] > stop_above;
      });
}

template <Executor Exec>
std::uint32_t ExecProbe<Exec>::scan(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> out) {
  return ex.exclusive_scan(in.data, out.data, in.size);
}

template <Executor Exec>
void ExecProbe<Exec>::sort(const Exec& ex, View<std::uint32_t> keys, View<std::int32_t> values, int bits) {
  ex.sort_by_key(keys.data, values.data, keys.size, bits);
}

template <Executor Exec>
void ExecProbe<Exec>::histogram(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> counts) {
  const auto bins = static_cast<std::uint32_t>(counts.size);
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { atomic_add(&counts[in[i] % bins], 1u); });
}

template <Executor Exec>
void ExecProbe<Exec>::atomic_float_sum(const Exec& ex, View<const float> in, float* total) {
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { atomic_add(total, in[i]); });
}

}  // namespace seamless::probe
