#include "core/exec.hpp"
#include "lanes_probe.hpp"

namespace seamless::probe {

template <Executor Exec>
void LanesProbe<Exec>::grouped_sums(const Exec& ex, const int* counts, const float* vals, std::int64_t n, int cap, int max_lanes,
                  SumCount* out) {
  ex.for_each_grouped(n, max_lanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    SumCount part;
    for (int k = g.lane, m = counts[i]; k < m; k += g.size) part = part + SumCount{vals[i * cap + k], 1};
    const SumCount total = g.sum(part);
    // Every lane holds the same total; the last lane writes it (not only lane 0 can).
    if (g.lane == g.size - 1) out[i] = total;
  });
}

template <Executor Exec>
void LanesProbe<Exec>::grouped_compact(const Exec& ex, const int* counts, const float* vals, std::int64_t n, int cap, int max_lanes,
                     int* kept, int* nkept) {
  ex.for_each_grouped(n, max_lanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    int cnt = 0;
    const int m = counts[i];
    for (int base = 0; base < m; base += g.size) {  // the same trip count in every lane
      const int k = base + g.lane;
      const bool keep = k < m && (static_cast<int>(vals[i * cap + (k < m ? k : 0)]) & 1);
      int total = 0;
      const int slot = cnt + g.rank(keep, &total);
      if (keep) kept[i * cap + slot] = k;
      cnt += total;
    }
    if (g.lane == 0) nkept[i] = cnt;
  });
}

// The phases' ranges, by value into the lambda (at most 64 phases here).
struct PhaseRanges {
  std::int64_t b[64], e[64];
};

template <Executor Exec>
void LanesProbe<Exec>::phase_chain(const Exec& ex, std::uint32_t* a, std::uint32_t* b, std::int64_t m, int phases,
                 const std::int64_t* begin, const std::int64_t* end) {
  // Each phase writes all of dst: the phase's range computes, the rest copies. Expressed as
  // phases over [0, m) with the range as data, so that the executor sees m-element phases.
  std::int64_t all_begin[64], all_end[64];
  PhaseRanges r{};
  for (int p = 0; p < phases; ++p) all_begin[p] = 0, all_end[p] = m, r.b[p] = begin[p], r.e[p] = end[p];
  ex.for_each_phases(phases, all_begin, all_end, [=] SEAMLESS_HD(int p, std::int64_t i) {
    const std::uint32_t* src = p % 2 == 0 ? a : b;
    std::uint32_t* dst = p % 2 == 0 ? b : a;
    const bool in = i >= r.b[p] && i < r.e[p];
    dst[i] = in ? src[i] + 3u * src[(i + 1) % m] : src[i];
  });
}

}  // namespace seamless::probe
