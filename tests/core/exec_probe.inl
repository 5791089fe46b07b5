#include "core/atomics.hpp"
#include "exec_probe.hpp"

namespace seamless::probe {

template <class Exec>
void square(const Exec& ex, View<const float> in, View<float> out) {
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { out[i] = in[i] * in[i]; });
}

template <class Exec>
Moments moments(const Exec& ex, View<const float> in) {
  return ex.transform_reduce(in.size, Moments{}, [=] SEAMLESS_HD(std::int64_t i) {
    double v = in[i];
    return Moments{v, v * v, 1};
  });
}

template <class Exec>
void moments_into(const Exec& ex, View<const float> in, Moments* out) {
  ex.transform_reduce_into(in.size, [=] SEAMLESS_HD(std::int64_t i) {
    double v = in[i];
    return Moments{v, v * v, 1};
  }, out);
}

template <class Exec>
void doubling_rounds(const Exec& ex, View<const float> in, int rounds, double stop_above, RoundSums* out,
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

template <class Exec>
std::uint32_t scan(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> out) {
  return ex.exclusive_scan(in.data, out.data, in.size);
}

template <class Exec>
void sort(const Exec& ex, View<std::uint32_t> keys, View<std::int32_t> values, int bits) {
  ex.sort_by_key(keys.data, values.data, keys.size, bits);
}

template <class Exec>
void histogram(const Exec& ex, View<const std::uint32_t> in, View<std::uint32_t> counts) {
  const auto bins = static_cast<std::uint32_t>(counts.size);
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { atomic_add(&counts[in[i] % bins], 1u); });
}

template <class Exec>
void atomic_float_sum(const Exec& ex, View<const float> in, float* total) {
  ex.for_each(in.size, [=] SEAMLESS_HD(std::int64_t i) { atomic_add(total, in[i]); });
}

}  // namespace seamless::probe

#define SEAMLESS_INSTANTIATE_PROBE(EXEC)                                                                     \
  namespace seamless::probe {                                                                                \
  template void square<EXEC>(const EXEC&, View<const float>, View<float>);                                   \
  template Moments moments<EXEC>(const EXEC&, View<const float>);                                            \
  template void moments_into<EXEC>(const EXEC&, View<const float>, Moments*);                                \
  template void doubling_rounds<EXEC>(const EXEC&, View<const float>, int, double, RoundSums*, RoundsLog*);       \
  template std::uint32_t scan<EXEC>(const EXEC&, View<const std::uint32_t>, View<std::uint32_t>);           \
  template void sort<EXEC>(const EXEC&, View<std::uint32_t>, View<std::int32_t>, int);                       \
  template void histogram<EXEC>(const EXEC&, View<const std::uint32_t>, View<std::uint32_t>);               \
  template void atomic_float_sum<EXEC>(const EXEC&, View<const float>, float*);                              \
  }
