// The depth camera's colliders computed on the device (DeviceColliders,
// kernels/physics/depth_colliders.hpp) give what the host oracle gives (host_colliders.hpp:
// depth_surface, the app's block_any and MovingColliders): on the CPU bit for bit; DeviceCollidersParity (ctest label
// gpu) on CUDA within float rounding.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "host_colliders.hpp"
#include "physics/depth_colliders.hpp"

namespace seamless {
namespace {

// A 40x30 pyramid level (f = 40 px) of a 160x120 frame (the mask's resolution, 4x4 pixels a level
// pixel), seeing a wavy surface about 1.5 m away that moves 2 cm away from the camera between
// frames while the camera turns and moves a few millimetres. Some pixels have no reading, some no normal.
constexpr int kW = 40, kH = 30, kScale = 4;
constexpr float kF = 40.f;

struct Maps {
  std::vector<vec3> v, n;
};

Maps view(int frame) {
  Maps m{std::vector<vec3>(kW * kH), std::vector<vec3>(kW * kH)};
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * kW + x;
      if ((x * 3 + y * 5) % 17 == 0) continue;  // no reading (z = 0)
      const float z = 1.5f + 0.1f * std::sin(0.3f * x) + 0.05f * std::cos(0.4f * y) + 0.02f * frame;
      m.v[i] = {(x - 0.5f * kW) / kF * z, (y - 0.5f * kH) / kF * z, z};
      if ((x + 2 * y) % 11 != 0)
        m.n[i] = normalize(vec3{0.03f * std::cos(0.3f * x), -0.02f * std::sin(0.4f * y), -1.f});
    }
  return m;
}

SE3 pose(int frame) {
  const float a = 0.002f * frame, c = std::cos(a), s = std::sin(a);
  SE3 T = SE3::identity();
  T.R = {{{c, 0.f, s}, {0.f, 1.f, 0.f}, {-s, 0.f, c}}};
  T.t = {0.1f + 0.001f * frame, 0.7f, 2.f};
  return T;
}

// The full-resolution dynamic mask: scattered pixels and one block.
std::vector<std::uint8_t> full_mask() {
  std::vector<std::uint8_t> m(kW * kScale * kH * kScale, 0);
  for (int Y = 0; Y < kH * kScale; ++Y)
    for (int X = 0; X < kW * kScale; ++X)
      if ((X * 7 + Y * 13) % 29 == 0 || (X > 60 && X < 100 && Y > 30 && Y < 70))
        m[static_cast<std::size_t>(Y) * kW * kScale + X] = 1;
  return m;
}

// The app's host code before the device path (src/app/pipeline.cpp, block_any, before the live loop moved to live.cpp):
// a level pixel is dynamic when any full-resolution pixel it averages is.
std::vector<std::uint8_t> block_any(const std::vector<std::uint8_t>& m, int W, int H, int w, int h) {
  std::vector<std::uint8_t> out(static_cast<std::size_t>(w) * h, 0);
  const int sx = W / w, sy = H / h;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
      if (m[static_cast<std::size_t>(y) * W + x] && x / sx < w && y / sy < h)
        out[static_cast<std::size_t>(y / sy) * w + x / sx] = 1;
  return out;
}

enum class MaskMode { all, mask, no_mask_yet };

// Three frames at 30 Hz through both paths; the colliders halfway between the last two frames.
struct Result {
  std::vector<vec3> points, velocities, colliders;
};

constexpr float kSpacing = 0.04f, kThickness = 0.1f, kMaxSpeed = 3.f;  // r = 0.1 m at 30 Hz: ~3x3 pixels searched
constexpr double kDt = 1.0 / 30.0;

Result host(MaskMode mode) {
  MovingColliders c(kSpacing, kThickness, kMaxSpeed);
  std::vector<std::uint8_t> mask;
  if (mode == MaskMode::mask) mask = block_any(full_mask(), kW * kScale, kH * kScale, kW, kH);
  if (mode == MaskMode::no_mask_yet) mask.assign(kW * kH, 0);
  DepthSurface last;
  for (int f = 0; f < 3; ++f) {
    const Maps m = view(f);
    last = depth_surface(m.v, m.n, kW, kH, pose(f), mask);
    c.update(last, f * kDt);
  }
  return {last.points, c.velocities(), c.at(1.5 * kDt)};
}

template <class T> std::vector<T> first(const Buffer<T>& b, std::int64_t n) {
  std::vector<T> v = b.to_host();
  v.resize(static_cast<std::size_t>(n));
  return v;
}

Result device(MaskMode mode, Device dev) {
  DeviceColliders c(kSpacing, kThickness, kMaxSpeed, dev);
  std::optional<Image<std::uint8_t>> mask;
  if (mode == MaskMode::mask) mask = Image<std::uint8_t>::from_host(full_mask(), kW * kScale, kH * kScale, dev);
  if (mode == MaskMode::no_mask_yet) mask.emplace();  // an empty image: the first frame's
  for (int f = 0; f < 3; ++f) {
    const Maps m = view(f);
    c.update(Image<vec3>::from_host(m.v, kW, kH, dev), Image<vec3>::from_host(m.n, kW, kH, dev), pose(f),
             mask ? &*mask : nullptr, f * kDt);
  }
  const std::int64_t n = c.at(1.5 * kDt);
  return {first(c.surface_points(), c.size()), first(c.velocities(), c.size()), first(c.points(), n)};
}

bool same(vec3 a, vec3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

std::size_t differing(const std::vector<vec3>& a, const std::vector<vec3>& b, float tol) {
  EXPECT_EQ(a.size(), b.size());
  std::size_t d = 0;
  for (std::size_t i = 0; i < std::min(a.size(), b.size()); ++i)
    d += tol == 0.f ? !same(a[i], b[i]) : !(length(a[i] - b[i]) <= tol);
  return d;
}

std::size_t moving(const std::vector<vec3>& v) {
  return static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [](vec3 u) { return length(u) > 0.1f; }));
}

// The same kernels' expressions on the CPU as the host loops: the same floats.
TEST(DeviceColliders, SameAsTheHostCodeOnTheCpu) {
  for (MaskMode mode : {MaskMode::all, MaskMode::mask}) {
    const Result h = host(mode), d = device(mode, Device::CPU);
    // The test can tell: points seen, most of them moving (2 cm over 1/30 s is 0.6 m/s).
    EXPECT_GT(h.points.size(), mode == MaskMode::all ? 1000u : 100u);
    EXPECT_GT(moving(h.velocities), h.points.size() / 2);
    EXPECT_EQ(differing(h.points, d.points, 0.f), 0u);
    EXPECT_EQ(differing(h.velocities, d.velocities, 0.f), 0u);
    EXPECT_EQ(h.colliders.size(), h.points.size() * 3);  // thickness 0.1 m: 2 layers behind each point
    EXPECT_EQ(differing(h.colliders, d.colliders, 0.f), 0u);
  }
  const Result none = device(MaskMode::no_mask_yet, Device::CPU);
  EXPECT_TRUE(host(MaskMode::no_mask_yet).points.empty());
  EXPECT_TRUE(none.points.empty());
  EXPECT_TRUE(none.colliders.empty());
}

TEST(DeviceColliders, MismatchedMapsAreAnError) {
  DeviceColliders c(kSpacing, kThickness, kMaxSpeed, Device::CPU);
  const Image<vec3> v(kW, kH, Device::CPU), n(kW, kH - 1, Device::CPU);
  EXPECT_THROW(c.update(v, n, SE3::identity(), nullptr, 0.0), Error);
}

// On CUDA the transforms and distances may contract to FMAs: positions of ~2 m then differ by a
// few float ulps (~1e-6 m; 1e-5 m bounds it), velocities by that over 1/30 s (~3e-5 m/s; 3e-4 m/s
// bounds it). The nearest previous point is the same pixel's (about 2 cm away; the next pixel is
// about 4 cm away), so no choice of neighbour turns on rounding.
TEST(DeviceCollidersParity, CudaGivesTheHostCodesColliders) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  for (MaskMode mode : {MaskMode::all, MaskMode::mask}) {
    const Result h = host(mode), d = device(mode, Device::CUDA);
    EXPECT_EQ(differing(h.points, d.points, 1e-5f), 0u);
    EXPECT_EQ(differing(h.velocities, d.velocities, 3e-4f), 0u);
    EXPECT_EQ(differing(h.colliders, d.colliders, 1e-5f), 0u);
  }
  EXPECT_TRUE(device(MaskMode::no_mask_yet, Device::CUDA).colliders.empty());
}

}  // namespace
}  // namespace seamless
