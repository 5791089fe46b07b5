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

// The colliders' check (InsidePeopleCheck, DepthColliders::inside) on a hand-made frame: a
// 160x120 mask (f = 100 px) over a 40x30 level that sees a wall 2 m in front of the camera
// everywhere; the mask marks a person on the block of full-resolution pixels [40, 80) x [40, 80),
// one of whose level pixels, (12, 12), has no reading. The camera is turned and moved, the
// particles are given in world coordinates. A particle is put on the ray of pixel (X, Y) at a
// distance b behind the wall along that ray: its depth is z = 2 + b / s, s = |ray| / ray.z, so
// (z - 2) * s = b exactly as the check measures it.
namespace inside {

constexpr int kMaskW = 160, kMaskH = 120, kMaskScale = 4;
constexpr float kWall = 2.f, kMargin = 0.015f, kShell = 0.15f;
constexpr int kRest = 3;
const Intrinsics kK{100.f, 100.f, 79.5f, 59.5f, kMaskW, kMaskH};

SE3 camera_pose() {
  const float a = 0.3f, c = std::cos(a), s = std::sin(a);
  SE3 T = SE3::identity();
  T.R = {{{c, -s, 0.f}, {s, c, 0.f}, {0.f, 0.f, 1.f}}};
  T.t = {0.5f, -0.2f, 1.f};
  return T;
}

Image<std::uint8_t> mask(Device d) {
  std::vector<std::uint8_t> m(kMaskW * kMaskH, 0);
  for (int Y = 40; Y < 80; ++Y)
    for (int X = 40; X < 80; ++X) m[static_cast<std::size_t>(Y) * kMaskW + X] = 1;
  return Image<std::uint8_t>::from_host(m, kMaskW, kMaskH, d);
}

Image<vec3> level(Device d) {
  const Intrinsics k = kK.level(2);
  std::vector<vec3> v(static_cast<std::size_t>(k.width) * k.height);
  for (int y = 0; y < k.height; ++y)
    for (int x = 0; x < k.width; ++x)
      if (x != 12 || y != 12) v[static_cast<std::size_t>(y) * k.width + x] = k.unproject(x, y, kWall);
  return Image<vec3>::from_host(v, k.width, k.height, d);
}

// In world coordinates: on pixel (X, Y)'s ray (plus a fraction of a pixel), b metres behind the wall.
vec3 at(float X, float Y, float b) {
  const vec3 ray = kK.unproject(X, Y, 1.f);
  return camera_pose() * (ray * (kWall + b / length(ray)));
}

struct Case {
  vec3 p;
  bool inside;
};

std::vector<Case> cases() {
  return {
      {at(60.f, 60.f, 0.05f), true},                  // in the person, 5 cm behind the surface
      {at(41.3f, 78.6f, 0.14f), true},                // near the mask's corner, near the shell's back
      {at(60.f, 60.f, 0.01f), false},                 // less than the margin behind: touching, not inside
      {at(60.f, 60.f, -0.05f), false},                // in front of the person
      {at(60.f, 60.f, 0.2f), false},                  // behind the shell: behind the person
      {at(20.f, 60.f, 0.05f), false},                 // behind the wall where nobody is (no mask)
      {at(39.4f, 60.f, 0.05f), false},                // next to the mask's edge (nearest pixel 39)
      {at(49.f, 50.f, 0.05f), false},                 // on the level pixel (12, 12) without a reading
      {at(200.f, 60.f, 0.05f), false},                // outside the image
      {camera_pose() * vec3{0.f, 0.f, -1.f}, false},  // behind the camera
  };
}

std::vector<vec3> positions(const std::vector<Case>& c) {
  std::vector<vec3> p;
  for (const Case& e : c) p.push_back(e.p);
  return p;
}

}  // namespace inside

TEST(InsidePeopleCheck, CountsTheParticlesInsideTheShellAndThoseThatStay) {
  using namespace inside;
  const std::vector<Case> c = cases();
  const std::int64_t expected = std::count_if(c.begin(), c.end(), [](const Case& e) { return e.inside; });
  ASSERT_EQ(expected, 2);
  const Image<std::uint8_t> m = mask(Device::CPU);
  const Image<vec3> lv = level(Device::CPU);
  // Each case alone: inside exactly where expected.
  for (const Case& e : c) {
    InsidePeopleCheck one(kMargin, kShell, kRest, Device::CPU);
    const Buffer<vec3> p = Buffer<vec3>::from_host({e.p}, Device::CPU);
    EXPECT_EQ(one.check(p.data(), 1, camera_pose(), kK, m, lv, 0).inside, e.inside ? 1 : 0);
  }
  // Frame after frame: the two inside particles rest from the (kRest + 1)-th frame on; a particle
  // spawned on frame 2 inside the person starts its own count; on frame 6 the first particle is
  // pushed out (its run ends) and on frame 7 it is back (a new run).
  InsidePeopleCheck check(kMargin, kShell, kRest, Device::CPU);
  std::vector<vec3> p = positions(c);
  const std::vector<std::int64_t> inside_now = {2, 2, 3, 3, 3, 3, 2, 3};
  const std::vector<std::int64_t> resting_now = {0, 0, 0, 2, 2, 3, 2, 2};
  for (std::int64_t f = 0; f < 8; ++f) {
    if (f == 2) p.push_back(at(70.f, 45.f, 0.1f));
    p[0] = at(60.f, 60.f, f == 6 ? -0.05f : 0.05f);
    const Buffer<vec3> b = Buffer<vec3>::from_host(p, Device::CPU);
    const kernels::InsideCount k =
        check.check(b.data(), static_cast<std::int64_t>(p.size()), camera_pose(), kK, m, lv, f);
    EXPECT_EQ(k.inside, inside_now[f]) << "frame " << f;
    EXPECT_EQ(k.resting, resting_now[f]) << "frame " << f;
  }
  const InsidePeopleStats& s = check.stats();
  EXPECT_EQ(s.frames_checked, 8);
  EXPECT_EQ(s.max_inside, 3);
  EXPECT_EQ(s.max_inside_frame, 2);
  EXPECT_EQ(s.frames_resting, 5);
  EXPECT_EQ(s.max_resting, 3);
  // A frame without a mask (none computed yet): nothing inside, every run ends.
  const Buffer<vec3> b = Buffer<vec3>::from_host(p, Device::CPU);
  EXPECT_EQ(check.check(b.data(), static_cast<std::int64_t>(p.size()), camera_pose(), kK, Image<std::uint8_t>(), lv, 8)
                .inside,
            0);
  EXPECT_EQ(check.check(b.data(), static_cast<std::int64_t>(p.size()), camera_pose(), kK, m, lv, 9).resting, 0);
}

TEST(InsidePeopleCheck, BadSettingsAndMapsAreErrors) {
  using namespace inside;
  EXPECT_THROW(InsidePeopleCheck(0.2f, 0.1f, kRest, Device::CPU), Error);  // margin past the shell
  InsidePeopleCheck check(kMargin, kShell, kRest, Device::CPU);
  const Buffer<vec3> p = Buffer<vec3>::from_host({at(60.f, 60.f, 0.05f)}, Device::CPU);
  const Image<vec3> odd(kMaskW / 3, kMaskH / 3, Device::CPU);  // 53 does not divide 160
  EXPECT_THROW(check.check(p.data(), 1, camera_pose(), kK, mask(Device::CPU), odd, 0), Error);
}

// CUDA against the CPU on a field of particles around the person, none within 2 mm of the margin
// or the shell's back and none within a quarter pixel of a pixel's border (so that rounding, FMA
// contraction on CUDA, cannot move one across): the same runs, frame after frame.
TEST(InsidePeopleCheckParity, CudaCountsAsTheCpu) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  using namespace inside;
  std::vector<vec3> p;
  for (int Y = 30; Y < 90; Y += 3)
    for (int X = 30; X < 90; X += 2)
      for (float b : {-0.05f, 0.005f, 0.03f, 0.1f, 0.16f}) p.push_back(at(X + 0.2f, Y - 0.2f, b));
  const auto n = static_cast<std::int64_t>(p.size());
  std::vector<kernels::InsideCount> counts[2];
  const Device devs[2] = {Device::CPU, Device::CUDA};
  for (int d = 0; d < 2; ++d) {
    InsidePeopleCheck check(kMargin, kShell, kRest, devs[d]);
    const Image<std::uint8_t> m = mask(devs[d]);
    const Image<vec3> lv = level(devs[d]);
    for (int f = 0; f < 5; ++f) {
      const Buffer<vec3> b = Buffer<vec3>::from_host(p, devs[d]);
      counts[d].push_back(check.check(b.data(), n, camera_pose(), kK, m, lv, f));
    }
  }
  // On the mask ([40, 80)): 13 of the rows, 20 of the columns; 2 of the 5 depths inside; but the 4
  // positions on the level pixel without a reading (X 48, 50; Y 48, 51).
  EXPECT_EQ(counts[0][0].inside, 2 * 13 * 20 - 2 * 4);
  for (int f = 0; f < 5; ++f) {
    EXPECT_EQ(counts[0][f].inside, counts[1][f].inside) << "frame " << f;
    EXPECT_EQ(counts[0][f].resting, counts[1][f].resting) << "frame " << f;
  }
  EXPECT_EQ(counts[1][4].resting, counts[1][4].inside);
}

}  // namespace
}  // namespace seamless
