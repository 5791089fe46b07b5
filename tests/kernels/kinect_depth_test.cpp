// kernels/io/kinect_depth: Kinect v1 disparity to metres and registration to the colour camera,
// against hand-computed values (the real recording against libfreenect: tests/io/test_kinect.cpp).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "core/exec_cpu.hpp"
#include "kernels/io/kinect_depth.hpp"

using namespace seamless;
using kernels::KinectDisparityModel;

namespace {
// A round model: z0 = 1 m, 2 f e = 100 m px, const_shift 100, f b = 10 px m: raw = 4 (c + 3/8) is
// the reference plane, and each raw step of -4 adds 1/100 to 1/z.
KinectDisparityModel round_model() {
  KinectDisparityModel m;
  m.inv_z0 = 1.f;
  m.inv_2fe = 0.01f;
  m.const_shift = 100.f;
  m.fb = 10.f;
  return m;
}

std::vector<float> run(const KinectDisparityModel& m, const std::vector<std::uint16_t>& raw,
                       const std::vector<vec2>& table, int w, int h, Device dev, bool registered) {
  auto r = Image<std::uint16_t>::from_host(raw, w, h, dev);
  auto t = Image<vec2>::from_host(table, w, h, dev);
  Image<std::uint32_t> zbuf(w, h, dev);
  Image<float> out(w, h, dev);
  with_exec(dev, [&]<class E>(const E& ex) {
    if (registered) kernels::KinectDepth<E>::register_to_colour(ex, m, r.cview(), t.cview(), zbuf.view(), out.view());
    else kernels::KinectDepth<E>::raw_to_metres(ex, m, r.cview(), out.view());
  });
  return out.to_host();
}
}  // namespace

TEST(KinectDepth, DisparityToMetres) {
  const KinectDisparityModel m = round_model();
  // raw 401.5 would be the reference plane (4 x 100.375); raw 401: 1/z = 1 + 0.125 x 0.01.
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 401), 1.0 / 1.00125, 1e-6);
  // raw 201.5 -> 1/z = 1 + 50 x 0.01 = 1.5.
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 201), 1.0 / (1.0 + 50.125 * 0.01), 1e-6);
  // 1/z <= 0 past raw = 4 (100.375 + 100) = 801.5: no reading; 2047: no reading.
  EXPECT_EQ(kernels::kinect_raw_to_metres(m, 802), 0.f);
  EXPECT_EQ(kernels::kinect_raw_to_metres(m, 2047), 0.f);
  // Beyond max_depth (10 m: 1/z < 0.1, raw > 4 (100.375 + 90) = 761.5): no reading.
  EXPECT_GT(kernels::kinect_raw_to_metres(m, 761), 9.f);
  EXPECT_EQ(kernels::kinect_raw_to_metres(m, 762), 0.f);
  std::vector<std::uint16_t> raw = {401, 201, 2047, 802};
  std::vector<vec2> table(4, vec2{0, 0});
  auto z = run(m, raw, table, 4, 1, Device::CPU, false);
  EXPECT_NEAR(z[0], 1.0 / 1.00125, 1e-6);
  EXPECT_EQ(z[2], 0.f);
  EXPECT_EQ(z[3], 0.f);
}

TEST(KinectDepth, RegistrationShiftsByParallaxAndKeepsTheNearest) {
  const KinectDisparityModel m = round_model();
  const int w = 8, h = 2;
  // Every pixel maps to itself before parallax (table = its own column, row), except the last
  // column of row 1, which lies outside the colour image.
  std::vector<vec2> table(w * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) table[y * w + x] = {static_cast<float>(x), static_cast<float>(y)};
  table[1 * w + 7].x = -1.f;
  std::vector<std::uint16_t> raw(w * h, 2047);
  // parallax(z) = 10 (1 - 1/z) + 3/8 pixels.
  raw[0 * w + 5] = 401;  // 1/z = 1.00125: parallax 0.3625, lands at 5.36 -> column 5
  raw[0 * w + 1] = 0;    // 1/z = 2.00375: parallax -9.66, off the left edge
  raw[1 * w + 2] = 721;  // 1/z = 0.20125: parallax 8.36, lands at 10.36, off the right edge
  raw[1 * w + 3] = 401;  // 1/z = 1.00125: lands at 3.36 -> column 3
  raw[1 * w + 4] = 385;  // 1/z = 1.04125: parallax -0.0375, lands at 3.96 -> column 3 too, and nearer
  raw[1 * w + 7] = 401;  // outside by the table
  auto z = run(m, raw, table, w, h, Device::CPU, true);
  for (int x = 0; x < w; ++x) {
    const float want0 = x == 5 ? 1.f / 1.00125f : 0.f;
    EXPECT_NEAR(z[x], want0, 1e-6) << x;
  }
  // Pixel (3, 1): the nearer of 1/1.00125 and 1/1.04125 m.
  EXPECT_NEAR(z[1 * w + 3], 1.f / 1.04125f, 1e-6);
  for (int x = 0; x < w; ++x) {
    if (x != 3) {
      EXPECT_EQ(z[1 * w + x], 0.f) << x;
    }
  }
}

// Both backends evaluate the same float expressions; CUDA may contract them into fused
// multiply-adds: a depth differs by an ulp (1e-7 relative), a column position crosses a pixel
// border only when within an ulp of it. Compared: the depths where both have one, and the count of
// pixels that have one on only one side (at most a few of 300k).
TEST(KinectDepthParity, CpuMatchesCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  KinectDisparityModel m;
  m.inv_z0 = 1 / 1.2f, m.inv_2fe = 1 / 86.37f, m.const_shift = 200, m.fb = 13.82f;
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> u(400, 1100);
  const int w = 640, h = 480;
  std::vector<std::uint16_t> raw(w * h);
  std::vector<vec2> table(w * h);
  for (int i = 0; i < w * h; ++i) {
    raw[i] = static_cast<std::uint16_t>(u(rng) > 1040 ? 2047 : u(rng));
    table[i] = {0.91f * (i % w) + 20.3f, std::floor(0.9f * (i / w) + 18.f)};
  }
  for (bool registered : {false, true}) {
    auto a = run(m, raw, table, w, h, Device::CPU, registered), b = run(m, raw, table, w, h, Device::CUDA, registered);
    int one_sided = 0;
    for (int i = 0; i < w * h; ++i) {
      if ((a[i] > 0) != (b[i] > 0)) {
        ++one_sided;
        continue;
      }
      ASSERT_NEAR(a[i], b[i], 2e-6f * a[i]) << i;
    }
    EXPECT_LE(one_sided, 10) << registered;
  }
}
