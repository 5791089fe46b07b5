// kernels/io/fill_gaps: one-pixel gaps of forward-registered depth, against hand-made images.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "core/exec_cpu.hpp"
#include "kernels/io/fill_gaps.hpp"

using namespace seamless;

namespace {
std::vector<float> fill(const std::vector<float>& d, int w, int h, Device dev = Device::CPU) {
  auto in = Image<float>::from_host(d, w, h, dev);
  Image<float> out(w, h, dev);
  with_exec(dev, [&]<class E>(const E& ex) {
    kernels::FillGaps<E>::fill_depth_gaps(ex, in.cview(), out.view(), kernels::kFillGapsMaxRelDiff);
  });
  return out.to_host();
}
}  // namespace

TEST(FillGaps, GapsOnASurfaceAreInterpolated) {
  // A tilted plane, depth linear in x: 1 m + 1 cm per column, with every other column empty and an
  // empty row, like the frames_box_50 sample. A gap's left/right (and diagonal) neighbours lie on the
  // plane symmetrically, so their mean is the plane's depth at the gap: exact to float rounding.
  const int w = 12, h = 6;
  std::vector<float> d(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d[y * w + x] = (x % 2 == 1 || y == 3) ? 0.f : 1.f + 0.01f * x;
  std::vector<float> r = fill(d, w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const bool border = x == w - 1;  // its right neighbour is outside; up/down are gaps too
      if (border && (x % 2 == 1 || y == 3)) {
        EXPECT_EQ(r[y * w + x], 0.f) << x << "," << y;
      } else {
        EXPECT_NEAR(r[y * w + x], 1.f + 0.01f * x, 1e-6f) << x << "," << y;
      }
    }
}

TEST(FillGaps, EdgesAndWideHolesStayEmpty) {
  // Left half at 1.0 m, right half at 1.5 m, the column between empty: 50% apart, a discontinuity
  // (an object's edge), never bridged.
  const int w = 9, h = 3;
  std::vector<float> d(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) d[y * w + x] = x < 4 ? 1.f : x > 4 ? 1.5f : 0.f;
  std::vector<float> r = fill(d, w, h);
  for (int y = 0; y < h; ++y) EXPECT_EQ(r[y * w + 4], 0.f);
  // A 3x3 hole: its centre has no measured neighbour at all and stays empty; the hole's corner
  // (1, 1) lies between (0, 2) and (2, 0), both measured, and is filled from them.
  std::vector<float> hole(5 * 5, 2.f);
  for (int y = 1; y <= 3; ++y)
    for (int x = 1; x <= 3; ++x) hole[y * 5 + x] = 0.f;
  r = fill(hole, 5, 5);
  EXPECT_EQ(r[2 * 5 + 2], 0.f);
  EXPECT_EQ(r[1 * 5 + 1], 2.f);
  // Just within 3%: filled; just beyond: not.
  std::vector<float> near = {1.f, 0.f, 1.029f}, far = {1.f, 0.f, 1.031f};
  EXPECT_NEAR(fill(near, 3, 1)[1], 1.0145f, 1e-6f);
  EXPECT_EQ(fill(far, 3, 1)[1], 0.f);
}

// Both backends evaluate the same float expressions; CUDA may contract the mean into fused
// multiply-adds, a difference of an ulp (1e-7 at 1 m): 1e-6 leaves room.
TEST(FillGapsParity, CpuMatchesCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<float> d(640 * 480);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = u(rng) < 0.3f ? 0.f : 1.f + 0.002f * (i % 640) + 0.01f * u(rng);
  std::vector<float> a = fill(d, 640, 480, Device::CPU), b = fill(d, 640, 480, Device::CUDA);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_NEAR(a[i], b[i], 1e-6f) << i;
}
