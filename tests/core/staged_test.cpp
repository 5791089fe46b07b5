// Exec::for_each_phases_staged (core/exec.hpp) on every available backend: each phase sees the
// previous phase's writes (against a serial host run), and staging changes nothing: the arrays
// written back equal those of the same sweep through for_each_phases, bit for bit. The cases
// cover the executor's paths on CUDA: everything staged in one block, a first array too large
// for shared memory (skipped, the rest staged), arrays none of which fit, phases too large for
// one block (a launch each, nothing staged), and more phases than one launch takes.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <vector>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "staged_probe.hpp"

using namespace seamless;

namespace {

class StagedPhasesTest : public ::testing::TestWithParam<Device> {
 protected:
  void SetUp() override {
    if (GetParam() == Device::CUDA && !cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  }
  Device dev() const { return GetParam(); }
};

struct Case {
  std::int64_t m;      // ring size (even)
  std::int64_t reach;  // phases cover j in [0, reach) (reach <= m / 2)
  std::int64_t pad_n;  // the first staged array's size
  int phases;
};

struct Result {
  std::vector<float> x;
  std::vector<int> visits;
};

Result run(Device d, const Case& c, const std::vector<std::int64_t>& begin, const std::vector<std::int64_t>& end,
           const std::vector<float>& x0, const std::vector<float>& w, bool staged) {
  auto x = Buffer<float>::from_host(x0, d);
  auto visits = Buffer<int>::from_host(std::vector<int>(c.m, 0), d);
  auto dw = Buffer<float>::from_host(w, d);
  auto pad = Buffer<float>::from_host(std::vector<float>(c.pad_n, 1.f), d);
  with_exec(d, [&]<class E>(const E& ex) {
    probe::StagedProbe<E>::relax_ring(ex, x.data(), visits.data(), dw.data(), pad.data(), c.pad_n, c.m, c.phases,
                                      begin.data(), end.data(), staged);
    ex.synchronize();
  });
  return {x.to_host(), visits.to_host()};
}

TEST_P(StagedPhasesTest, PhasesSeeEachOtherAndStagingChangesNoBit) {
  const Case cases[] = {
      {3000, 1500, 7, 24},       // one block, all staged
      {3000, 1500, 7, 40},       // two launches of phases, each staging
      {3000, 1500, 200000, 24},  // the pad (800 KB) is skipped, x, visits and w staged
      {100000, 1000, 7, 24},     // x, visits, w (400 KB each) too large: only the pad staged
      {6000, 3000, 7, 12},       // phases of up to 3000 elements: a launch each
  };
  for (const Case& c : cases) {
    std::mt19937 rng(static_cast<unsigned>(c.m + c.pad_n + c.phases));
    std::vector<std::int64_t> begin(c.phases), end(c.phases);
    for (int p = 0; p < c.phases; ++p) {
      std::uniform_int_distribution<std::int64_t> d(0, c.reach);
      std::int64_t a = d(rng), b = d(rng);
      begin[p] = std::min(a, b), end[p] = std::max(a, b);
    }
    begin[0] = 0, end[0] = c.reach;  // at least one full phase
    std::uniform_real_distribution<float> ux(0.f, 1.f), uw(0.1f, 0.9f);
    std::vector<float> x0(c.m), w(c.m);
    for (auto& v : x0) v = ux(rng);
    for (auto& v : w) v = uw(rng);

    // The serial sweep on the host (float; the device may contract to FMA: a tolerance).
    std::vector<float> hx = x0;
    std::vector<int> hv(c.m, 0);
    for (int p = 0; p < c.phases; ++p)
      for (std::int64_t j = begin[p]; j < end[p]; ++j) {
        const std::int64_t i = 2 * j + p % 2;
        const float l = hx[(i + c.m - 1) % c.m], r = hx[(i + 1) % c.m];
        hx[i] += w[i] * (0.5f * (l + r) - hx[i]);
        hv[i] += 1;
      }

    const Result s = run(dev(), c, begin, end, x0, w, true);
    const Result u = run(dev(), c, begin, end, x0, w, false);
    const std::string what =
        "m " + std::to_string(c.m) + " pad " + std::to_string(c.pad_n) + " phases " + std::to_string(c.phases);
    EXPECT_EQ(s.visits, hv) << what;
    EXPECT_EQ(u.visits, hv) << what;
    ASSERT_EQ(s.x.size(), u.x.size());
    EXPECT_EQ(std::memcmp(s.x.data(), u.x.data(), sizeof(float) * s.x.size()), 0) << what << ": staged != unstaged";
    float worst = 0.f;
    for (std::int64_t i = 0; i < c.m; ++i) worst = std::max(worst, std::fabs(s.x[i] - hx[i]));
    EXPECT_LT(worst, 1e-5f) << what;
  }
}

// The CUDA instantiation carries "Parity" in its name: it gets the ctest label `gpu`.
auto device_label = [](const auto& info) { return std::string(device_name(info.param)); };
INSTANTIATE_TEST_SUITE_P(Cpu, StagedPhasesTest, ::testing::Values(Device::CPU), device_label);
INSTANTIATE_TEST_SUITE_P(CudaParity, StagedPhasesTest, ::testing::Values(Device::CUDA), device_label);

}  // namespace
