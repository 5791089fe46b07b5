// The executor primitives on every available backend, against exact host results. Inputs are
// small integers stored as floats, so every sum below is exact in float/double arithmetic and the
// comparisons can be exact whatever the summation order.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "exec_probe.hpp"

using namespace seamless;

namespace {

class ExecTest : public ::testing::TestWithParam<Device> {
 protected:
  void SetUp() override {
    if (GetParam() == Device::CUDA && !cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  }
  Device dev() const { return GetParam(); }
};

std::vector<std::uint32_t> random_keys(std::size_t n, std::uint32_t max, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<std::uint32_t> d(0, max);
  std::vector<std::uint32_t> v(n);
  for (auto& k : v) k = d(rng);
  return v;
}

TEST_P(ExecTest, ForEachCoversEveryElementOnce) {
  const std::int64_t n = 100003;  // not a multiple of any block size
  std::vector<float> h(n);
  for (std::int64_t i = 0; i < n; ++i) h[i] = static_cast<float>(i % 1000);
  auto in = Buffer<float>::from_host(h, dev());
  Buffer<float> out(n, dev());
  with_exec(dev(), [&]<class E>(const E& ex) { probe::ExecProbe<E>::square(ex, in.cview(), out.view()); });
  auto r = out.to_host();
  for (std::int64_t i = 0; i < n; ++i) ASSERT_EQ(r[i], h[i] * h[i]) << "at " << i;
}

TEST_P(ExecTest, TransformReduceOfStruct) {
  const std::int64_t n = 250001;
  std::vector<float> h(n);
  double sum = 0, sq = 0;
  for (std::int64_t i = 0; i < n; ++i) {
    h[i] = static_cast<float>(i % 17);
    sum += h[i];
    sq += double(h[i]) * h[i];
  }
  auto in = Buffer<float>::from_host(h, dev());
  auto m = with_exec(dev(), [&]<class E>(const E& ex) { return probe::ExecProbe<E>::moments(ex, in.cview()); });
  EXPECT_EQ(m.count, n);
  EXPECT_EQ(m.sum, sum);
  EXPECT_EQ(m.sum_sq, sq);
}

// The device-resident variant, run several times into one buffer: the "last block" counter must
// be back at zero after every reduction, and an empty range must write a zero sum.
TEST_P(ExecTest, TransformReduceIntoLeavesTheSumOnTheDevice) {
  for (std::int64_t n : {std::int64_t{250001}, std::int64_t{1}, std::int64_t{0}, std::int64_t{70000}}) {
    std::vector<float> h(static_cast<std::size_t>(n));
    double sum = 0;
    for (std::int64_t i = 0; i < n; ++i) sum += h[i] = static_cast<float>(i % 13);
    auto in = Buffer<float>::from_host(h, dev());
    auto out = Buffer<probe::Moments>::from_host({probe::Moments{-1.0, -1.0, -1}}, dev());  // poisoned
    with_exec(dev(), [&]<class E>(const E& ex) { probe::ExecProbe<E>::moments_into(ex, in.cview(), out.data()); });
    probe::Moments m = out.to_host()[0];
    EXPECT_EQ(m.count, n);
    EXPECT_EQ(m.sum, sum);
  }
}

// Rounds of reductions in one call: every round must see the state the previous round's `then`
// wrote (the sums double), and the rounds must stop at the first `then` that says so; every one of
// the 40 components must be summed (more than a warp's 32 lanes). The terms are small integers
// times (k + 1) times powers of two, and every partial sum stays below 2^24 times that power of
// two, so the float sums are exact in any order.
TEST_P(ExecTest, TransformReduceRoundsSeesEachRoundsUpdateAndStops) {
  for (std::int64_t n : {std::int64_t{25001}, std::int64_t{1000}, std::int64_t{1}}) {
    std::vector<float> h(static_cast<std::size_t>(n));
    double sum = 0;
    for (std::int64_t i = 0; i < n; ++i) sum += h[i] = static_cast<float>(i % 13);
    auto in = Buffer<float>::from_host(h, dev());
    for (int stop_after : {3, 10}) {  // stops early (3 of 10 rounds), or runs all 10
      auto out = Buffer<probe::RoundSums>::from_host({probe::RoundSums{}}, dev());
      auto log = Buffer<probe::RoundsLog>::from_host({probe::RoundsLog{}}, dev());
      // the sum of round r is sum x 2^r: exceeding sum x 2^(stop_after - 1) x 0.75 stops after stop_after rounds
      const double stop_above = sum * std::ldexp(1.0, stop_after - 1) * 0.75;
      with_exec(dev(), [&]<class E>(const E& ex) {
        probe::ExecProbe<E>::doubling_rounds(ex, in.cview(), 10, stop_above, out.data(), log.data());
      });
      const probe::RoundsLog l = log.to_host()[0];
      ASSERT_EQ(l.rounds_run, sum > 0 ? stop_after : 10) << "n " << n;
      for (int r = 0; r < l.rounds_run; ++r)
        for (int k = 0; k < 40; ++k)
          ASSERT_EQ(l.sums[r][k], sum * (k + 1) * std::ldexp(1.0, r)) << "round " << r << " component " << k;
      EXPECT_EQ(out.to_host()[0].v[39], sum * 40 * std::ldexp(1.0, l.rounds_run - 1));
    }
  }
}

TEST_P(ExecTest, ExclusiveScanAndTotal) {
  auto h = random_keys(77777, 9, 1);
  auto in = Buffer<std::uint32_t>::from_host(h, dev());
  Buffer<std::uint32_t> out(in.size(), dev());
  auto total =
      with_exec(dev(), [&]<class E>(const E& ex) { return probe::ExecProbe<E>::scan(ex, in.cview(), out.view()); });
  std::vector<std::uint32_t> expect(h.size());
  std::exclusive_scan(h.begin(), h.end(), expect.begin(), 0u);
  EXPECT_EQ(out.to_host(), expect);
  EXPECT_EQ(total, std::accumulate(h.begin(), h.end(), 0u));
}

TEST_P(ExecTest, SortByKeyIsStable) {
  for (int bits : {8, 20, 32}) {
    std::uint32_t max = bits == 32 ? 0xFFFFFFFFu : (1u << bits) - 1;
    auto keys = random_keys(50000, max, 2);
    std::vector<std::int32_t> vals(keys.size());
    std::iota(vals.begin(), vals.end(), 0);
    auto k = Buffer<std::uint32_t>::from_host(keys, dev());
    auto v = Buffer<std::int32_t>::from_host(vals, dev());
    with_exec(dev(), [&]<class E>(const E& ex) { probe::ExecProbe<E>::sort(ex, k.view(), v.view(), bits); });
    std::vector<std::int32_t> order(vals);
    std::stable_sort(order.begin(), order.end(), [&](int a, int b) { return keys[a] < keys[b]; });
    EXPECT_EQ(v.to_host(), order) << bits << " bits";
    std::sort(keys.begin(), keys.end());
    EXPECT_EQ(k.to_host(), keys) << bits << " bits";
  }
}

TEST_P(ExecTest, AtomicsUnderContention) {
  auto h = random_keys(200000, 1000, 3);
  auto in = Buffer<std::uint32_t>::from_host(h, dev());
  Buffer<std::uint32_t> counts(7, dev());
  counts.zero();
  with_exec(dev(), [&]<class E>(const E& ex) { probe::ExecProbe<E>::histogram(ex, in.cview(), counts.view()); });
  std::vector<std::uint32_t> expect(7, 0);
  for (auto x : h) ++expect[x % 7];
  EXPECT_EQ(counts.to_host(), expect);

  std::vector<float> ones(100000, 1.0f);  // 1e5 < 2^24: the float sum is exact in any order
  auto f = Buffer<float>::from_host(ones, dev());
  Buffer<float> total(1, dev());
  total.zero();
  with_exec(dev(), [&]<class E>(const E& ex) { probe::ExecProbe<E>::atomic_float_sum(ex, f.cview(), total.data()); });
  EXPECT_EQ(total.to_host()[0], 100000.0f);
}

// Buffer::zeros starts zero, and grow_zeroed keeps the contents and zeroes the new elements, from
// a zeroed buffer (on the host: mapped pages, grown by mremap) and from an ordinary one (copied),
// the ledger counting the grown size once. The sizes are not whole pages.
TEST_P(ExecTest, ZeroedBuffersGrowKeepingTheirContents) {
  const std::size_t before = memory::bytes_in_use(dev());
  for (bool zeroed : {true, false}) {
    const std::int64_t n = 3 * 4096 + 5, m = 5 * n + 7;
    Buffer<std::int32_t> b = zeroed ? Buffer<std::int32_t>::zeros(n, dev()) : Buffer<std::int32_t>(n, dev());
    if (zeroed) {
      const auto z = b.to_host();
      EXPECT_EQ(std::count(z.begin(), z.end(), 0), n);
    }
    std::vector<std::int32_t> v(n);
    std::iota(v.begin(), v.end(), 1);
    b.copy_from_host(v.data(), n);
    b.grow_zeroed(m);
    ASSERT_EQ(b.size(), m);
    EXPECT_EQ(memory::bytes_in_use(dev()), before + m * sizeof(std::int32_t));
    const auto h = b.to_host();
    EXPECT_TRUE(std::equal(v.begin(), v.end(), h.begin())) << "zeroed " << zeroed;
    EXPECT_EQ(std::count(h.begin() + n, h.end(), 0), m - n) << "zeroed " << zeroed;
    b.grow_zeroed(n);  // never shrinks
    EXPECT_EQ(b.size(), m);
  }
  EXPECT_EQ(memory::bytes_in_use(dev()), before);
}

// The CUDA instantiation carries "Parity" in its name: it gets the ctest label `gpu`.
auto device_label = [](const auto& info) { return std::string(device_name(info.param)); };
INSTANTIATE_TEST_SUITE_P(Cpu, ExecTest, ::testing::Values(Device::CPU), device_label);
INSTANTIATE_TEST_SUITE_P(CudaParity, ExecTest, ::testing::Values(Device::CUDA), device_label);

TEST(Buffer, MoveOwnsAndLedgerCounts) {
  std::size_t before = memory::bytes_in_use(Device::CPU);
  {
    Buffer<double> a(1000, Device::CPU);
    EXPECT_EQ(memory::bytes_in_use(Device::CPU), before + 8000);
    Buffer<double> b(std::move(a));
    EXPECT_EQ(a.data(), nullptr);
    EXPECT_EQ(b.size(), 1000);
    EXPECT_EQ(memory::bytes_in_use(Device::CPU), before + 8000);
  }
  EXPECT_EQ(memory::bytes_in_use(Device::CPU), before);
}

TEST(Device, CudaRequestWithoutCudaIsAClearError) {
  if (cuda_available()) GTEST_SKIP() << "a CUDA device is present";
  try {
    resolve_device("cuda");
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("--device cpu"), std::string::npos) << e.what();
  }
  EXPECT_EQ(resolve_device("auto"), Device::CPU);
  EXPECT_THROW(resolve_device("gpu"), Error);
}

}  // namespace
