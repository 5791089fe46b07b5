// The grouped executor collectives (core/exec.hpp: for_each_grouped with Lanes::sum and
// Lanes::rank, for_each_phases) on every available backend, against exact host results (sums of
// small integers in float are exact in any order).
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "lanes_probe.hpp"

using namespace seamless;

namespace {

class LanesTest : public ::testing::TestWithParam<Device> {
 protected:
  void SetUp() override {
    if (GetParam() == Device::CUDA && !cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  }
  Device dev() const { return GetParam(); }
};

constexpr int kCap = 40;

struct Lists {
  std::vector<int> counts;
  std::vector<float> vals;
};

Lists random_lists(std::int64_t n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> c(0, kCap), v(0, 100);
  Lists l{std::vector<int>(n), std::vector<float>(n * kCap, -1.f)};
  for (std::int64_t i = 0; i < n; ++i) {
    l.counts[i] = c(rng);
    for (int k = 0; k < l.counts[i]; ++k) l.vals[i * kCap + k] = static_cast<float>(v(rng));
  }
  return l;
}

TEST_P(LanesTest, LanesAreAPowerOfTwoWithinTheCap) {
  for (std::int64_t n : {1, 100, 10000, 1000000})
    for (int cap : {1, 3, 8, 16, 64}) {
      int g = with_exec(dev(), [&]<class E>(const E& ex) { return ex.lanes(n, cap); });
      EXPECT_GE(g, 1);
      EXPECT_LE(g, std::max(1, std::min(cap, 32)));
      EXPECT_EQ(g & (g - 1), 0) << g;
      if (dev() == Device::CPU) {
        EXPECT_EQ(g, 1);
      }
    }
}

TEST_P(LanesTest, GroupedSumsEqualTheSerialSums) {
  for (std::int64_t n : {1, 7, 1000, 30011})
    for (int max_lanes : {1, 4, 16, 32}) {
      Lists l = random_lists(n, static_cast<unsigned>(n + max_lanes));
      auto counts = Buffer<int>::from_host(l.counts, dev());
      auto vals = Buffer<float>::from_host(l.vals, dev());
      Buffer<probe::SumCount> out(n, dev());
      with_exec(dev(), [&]<class E>(const E& ex) {
        probe::LanesProbe<E>::grouped_sums(ex, counts.data(), vals.data(), n, kCap, max_lanes, out.data());
      });
      auto r = out.to_host();
      for (std::int64_t i = 0; i < n; ++i) {
        float sum = 0.f;
        for (int k = 0; k < l.counts[i]; ++k) sum += l.vals[i * kCap + k];
        ASSERT_EQ(r[i].sum, sum) << "n " << n << " lanes " << max_lanes << " at " << i;
        ASSERT_EQ(r[i].count, l.counts[i]) << "n " << n << " lanes " << max_lanes << " at " << i;
      }
    }
}

TEST_P(LanesTest, GroupedCompactionKeepsTheSerialOrder) {
  for (std::int64_t n : {5, 4099})
    for (int max_lanes : {1, 8, 32}) {
      Lists l = random_lists(n, static_cast<unsigned>(3 * n + max_lanes));
      auto counts = Buffer<int>::from_host(l.counts, dev());
      auto vals = Buffer<float>::from_host(l.vals, dev());
      Buffer<int> kept(n * kCap, dev()), nkept(n, dev());
      with_exec(dev(), [&]<class E>(const E& ex) {
        probe::LanesProbe<E>::grouped_compact(ex, counts.data(), vals.data(), n, kCap, max_lanes, kept.data(),
                                              nkept.data());
      });
      auto rk = kept.to_host();
      auto rn = nkept.to_host();
      for (std::int64_t i = 0; i < n; ++i) {
        std::vector<int> want;
        for (int k = 0; k < l.counts[i]; ++k)
          if (static_cast<int>(l.vals[i * kCap + k]) & 1) want.push_back(k);
        ASSERT_EQ(rn[i], static_cast<int>(want.size())) << "at " << i;
        for (std::size_t k = 0; k < want.size(); ++k) ASSERT_EQ(rk[i * kCap + k], want[k]) << "at " << i;
      }
    }
}

// Phases of one block (m = 500), of several launches (m = 3000 is over one block's share), and
// more phases than one launch takes (40).
TEST_P(LanesTest, EachPhaseSeesThePreviousOne) {
  for (std::int64_t m : {500, 3000}) {
    const int phases = 40;
    std::vector<std::int64_t> begin(phases), end(phases);
    std::mt19937 rng(static_cast<unsigned>(m));
    for (int p = 0; p < phases; ++p) {
      std::uniform_int_distribution<std::int64_t> d(0, m);
      std::int64_t x = d(rng), y = d(rng);
      begin[p] = std::min(x, y), end[p] = std::max(x, y);
    }
    std::vector<std::uint32_t> a(m), b(m, 0);
    for (std::int64_t i = 0; i < m; ++i) a[i] = static_cast<std::uint32_t>(i * 7 + 1);
    auto da = Buffer<std::uint32_t>::from_host(a, dev()), db = Buffer<std::uint32_t>::from_host(b, dev());
    with_exec(dev(), [&]<class E>(const E& ex) {
      probe::LanesProbe<E>::phase_chain(ex, da.data(), db.data(), m, phases, begin.data(), end.data());
    });
    for (int p = 0; p < phases; ++p) {  // the same chain on the host
      auto& src = p % 2 == 0 ? a : b;
      auto& dst = p % 2 == 0 ? b : a;
      for (std::int64_t i = 0; i < m; ++i)
        dst[i] = i >= begin[p] && i < end[p] ? src[i] + 3u * src[(i + 1) % m] : src[i];
    }
    EXPECT_EQ(da.to_host(), a) << "m " << m;
    EXPECT_EQ(db.to_host(), b) << "m " << m;
  }
}

// The CUDA instantiation carries "Parity" in its name: it gets the ctest label `gpu`.
auto device_label = [](const auto& info) { return std::string(device_name(info.param)); };
INSTANTIATE_TEST_SUITE_P(Cpu, LanesTest, ::testing::Values(Device::CPU), device_label);
INSTANTIATE_TEST_SUITE_P(CudaParity, LanesTest, ::testing::Values(Device::CUDA), device_label);

}  // namespace
