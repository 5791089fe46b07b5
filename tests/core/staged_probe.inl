#include "core/exec.hpp"
#include "staged_probe.hpp"

namespace seamless::probe {

SEAMLESS_HD inline void relax_one(int p, std::int64_t j, float* x, int* visits, const float* w, const float* pad,
                                  std::int64_t pad_n, std::int64_t m) {
  const std::int64_t i = 2 * j + p % 2;
  const float l = x[(i + m - 1) % m], r = x[(i + 1) % m];
  x[i] += w[i] * pad[i % pad_n] * (0.5f * (l + r) - x[i]);
  visits[i] += 1;
}

template <Executor Exec>
void StagedProbe<Exec>::relax_ring(const Exec& ex, float* x, int* visits, const float* w, const float* pad, std::int64_t pad_n,
                std::int64_t m, int phases, const std::int64_t* begin, const std::int64_t* end, bool staged) {
  if (!staged) {
    ex.for_each_phases(phases, begin, end, [=] SEAMLESS_HD(int p, std::int64_t j) {
      relax_one(p, j, x, visits, w, pad, pad_n, m);
    });
    return;
  }
  ex.for_each_phases_staged(
      phases, begin, end,
      [=] SEAMLESS_HD(int p, std::int64_t j, const float* pad_s, float* x_s, int* visits_s, const float* w_s) {
        relax_one(p, j, x_s, visits_s, w_s, pad_s, pad_n, m);
      },
      Staged<const float>{pad, pad_n}, Staged<float>{x, m}, Staged<int>{visits, m}, Staged<const float>{w, m});
}

}  // namespace seamless::probe
