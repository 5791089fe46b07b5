// The compute splats (render.fluid_splat: compute) against the raster sprites: the same sphere
// depth image and the same thickness, on the same renderer and particles.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>

#include "core/device.hpp"
#include "core/phase.hpp"
#include "physics/fluid_ellipsoids.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

constexpr float kNear = 0.05f, kWallZ = 2.f;

// A jittered 6 x 6 x 6 block about z = 2 m (spheres overlap at many depths: inner silhouettes),
// cut by a camera-facing wall at z = 2 m (some spheres partly behind the scene). Every centre
// projects inside the image: a point sprite whose centre leaves the view is clipped whole, a
// splat is not (docs/RENDERING.md), and that difference is not what this compares.
struct Block {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  float r = 0.02f;
  Block() {
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> j(-0.4f * r, 0.4f * r);
    for (int k = 0; k < 6; ++k)
      for (int jj = 0; jj < 6; ++jj)
        for (int i = 0; i < 6; ++i)
          x.push_back(
              vec3{(i - 2.5f) * 2 * r + j(rng), (jj - 2.5f) * 2 * r + j(rng), kWallZ + (k - 2.5f) * 2 * r + j(rng)});
    ph.assign(x.size(), phase::kFluid);
  }
  DrawList list() const {
    DrawList d;
    d.positions = x, d.phases = ph, d.particle_radius = r;
    return d;
  }
};

RenderParams splat_params(int thickness_downsample) {
  RenderParams p;
  p.znear = kNear;
  p.fluid_anisotropy = false;  // the raster sprites are spheres (docs/RENDERING.md)
  p.filter_iterations = 0;     // the depth image is then the spheres' own
  p.thickness_downsample = thickness_downsample;
  return p;
}

// Each path on its own renderer, so that no image of one can be left over for the other.
struct Drawn {
  Renderer::FluidImages fluid;
  bool compute = false;
  Image<uchar3> frame;
};
Drawn draw_with(RenderParams p, const Block& b, const Intrinsics& K, float wall_z, FluidSplat splat) {
  p.fluid_splat = splat;
  Renderer r(p, K.width, K.height);
  r.set_scene_mesh(rectangle(-2.f, 2.f, -2.f, 2.f, wall_z, uchar3{90, 120, 60}));
  r.draw(b.list(), camera(K));
  return {r.read_fluid_images(), r.uses_compute_splat(), r.read_frame()};
}

// Per window pixel of a w x h image with intrinsics K (rows bottom to top): how many spheres'
// sprite squares cover it, a bound on how many chords the pixel sums.
std::vector<int> chord_counts(const Block& b, const Intrinsics& K) {
  const float rs = b.r * RenderParams{}.fluid_radius_scale;
  std::vector<int> n(static_cast<std::size_t>(K.width) * K.height, 0);
  for (vec3 c : b.x) {
    const vec2 q = K.project(c);
    const float half = K.fx * rs / (c.z - rs) + 1.f;
    for (int y = 0; y < K.height; ++y)
      for (int x = 0; x < K.width; ++x)
        if (std::abs(q.x - x) <= half && std::abs(q.y - (K.height - 1 - y)) <= half)
          ++n[static_cast<std::size_t>(y) * K.width + x];
  }
  return n;
}

// The most of `n` within `reach` pixels of (x, y) (the thickness blur's square).
int most_within(const std::vector<int>& n, int w, int h, int x, int y, int reach) {
  int m = 0;
  for (int v = std::max(0, y - reach); v <= std::min(h - 1, y + reach); ++v)
    for (int u = std::max(0, x - reach); u <= std::min(w - 1, x + reach); ++u)
      m = std::max(m, n[static_cast<std::size_t>(v) * w + u]);
  return m;
}

bool on_outer_silhouette(const std::vector<float>& d, int w, int h, int x, int y) {
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u < 0 || v < 0 || u >= w || v >= h || d[static_cast<std::size_t>(v) * w + u] <= 0.f) return true;
    }
  return false;
}

// Depth tolerance. Both paths evaluate the same ray_sphere (sphere_hit.glsl) on the same eye-space
// centre and pixel ray, so a sphere's depth at a pixel is the same float. They can differ in which
// sphere wins: the raster path keeps the least *window* depth d = window_depth(z) in a 32F depth
// buffer, the splat the least eye depth z. d in [0.5, 1) has an ulp of 2^-24; allowing 4 ulp for
// window_depth's own rounding, spheres closer than 2^-22 / (dd/dz) tie, and dd/dz =
// f n / ((f - n) z^2) >= n / z^2. So |dz| <= 2^-22 z^2 / n (z = 2.2 m: 2.3e-5 m).
float depth_tol(float z) { return std::ldexp(1.f, -22) * z * z / kNear; }

TEST(RenderSplat, ComputeDepthMatchesRaster) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(400.f, 79.5f, 59.5f, 160, 120);
  const Block b;
  const auto ras = draw_with(splat_params(1), b, K, kWallZ, FluidSplat::raster).fluid;
  const Drawn c = draw_with(splat_params(1), b, K, kWallZ, FluidSplat::compute);
  if (!c.compute) GTEST_SKIP() << "no GL 4.3 compute here";
  const auto& cmp = c.fluid;
  ASSERT_EQ(ras.depth.size(), cmp.depth.size());
  int both = 0, silhouette = 0;
  for (int y = 0; y < ras.h; ++y)
    for (int x = 0; x < ras.w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * ras.w + x;
      const float a = ras.depth[i], c = cmp.depth[i];
      if ((a > 0.f) != (c > 0.f)) {
        // Only where a sphere's rim meets empty space (the discriminant's sign at a tangent ray)
        // or where it passes through the wall (a tie with the scene depth, tolerance as above).
        const float z = std::max(a, c);
        const bool at_wall = std::abs(z - kWallZ) <= depth_tol(z);
        EXPECT_TRUE(at_wall || on_outer_silhouette(a > 0.f ? ras.depth : cmp.depth, ras.w, ras.h, x, y))
            << "pixel set differs inside the fluid at " << x << "," << y << ": raster " << a << ", compute " << c;
        ++silhouette;
        continue;
      }
      if (a <= 0.f) continue;
      ++both;
      EXPECT_NEAR(c, a, depth_tol(a)) << "at " << x << "," << y;
      EXPECT_LT(a, kWallZ) << "fluid behind the wall at " << x << "," << y;
    }
  EXPECT_GT(both, 2000);             // the block covers about 60 x 60 pixels, partly cut by the wall
  EXPECT_LT(silhouette, both / 50);  // differences are rare rim pixels, not a shifted image
}

// Thickness tolerance per pixel: the splat rounds each chord to 2^-20 m (0.5 * 2^-20 each); the
// raster path sums floats (each addition off by half an ulp of the sum, <= T 2^-24); a sphere
// whose front ties with the wall (window-depth resolution as in depth_tol, along a ray up to 1.2
// times z, times the thickness scale 6 / (pi 1.5^3) < 0.6) may be rejected by the raster path's
// early depth test but keep a chord of that length in the splat. The Gaussian after both has
// weights summing to 1, so a bound on every pixel holds after it.
float thickness_tol(int chords, float t) {
  const float per_chord = std::ldexp(1.f, -21) + 1.2f * 0.6f * depth_tol(kWallZ + 0.1f);
  return static_cast<float>(chords) * (per_chord + t * std::ldexp(1.f, -24)) + 1e-6f;
}

void expect_same_thickness(int downsample) {
  const Intrinsics K = intrinsics(400.f, 79.5f, 59.5f, 160, 120);
  const Block b;
  const auto ras = draw_with(splat_params(downsample), b, K, kWallZ, FluidSplat::raster).fluid;
  const Drawn c = draw_with(splat_params(downsample), b, K, kWallZ, FluidSplat::compute);
  if (!c.compute) GTEST_SKIP() << "no GL 4.3 compute here";
  const auto& cmp = c.fluid;
  const Intrinsics Kt = scale_intrinsics(K, ras.tw, ras.th);
  // The blur (x then y) reaches 3 pixels: the most chords within that square bounds its error.
  const std::vector<int> counts = chord_counts(b, Kt);
  int covered = 0;
  float most = 0.f;
  for (int y = 0; y < ras.th; ++y)
    for (int x = 0; x < ras.tw; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * ras.tw + x;
      const float a = ras.thickness[i], c = cmp.thickness[i];
      if (a <= 0.f && c <= 0.f) continue;
      const int chords = most_within(counts, ras.tw, ras.th, x, y, 3);
      ASSERT_NEAR(c, a, thickness_tol(chords, a)) << "at " << x << "," << y << " (" << chords << " chords)";
      ++covered, most = std::max(most, a);
    }
  EXPECT_GT(covered, 2000 / (downsample * downsample));
  EXPECT_GT(most, 0.05f);  // several spheres deep: a real sum was compared, not just one chord
}

TEST(RenderSplat, ComputeThicknessMatchesRasterFullResolution) {
  SEAMLESS_REQUIRE_EGL();
  expect_same_thickness(1);
}

TEST(RenderSplat, ComputeThicknessMatchesRasterHalfResolution) {
  SEAMLESS_REQUIRE_EGL();
  expect_same_thickness(2);
}

// The default is the compute path where GL 4.3 is there (Mesa: 4.5), and the setting switches it.
TEST(RenderSplat, DefaultIsComputeAndRasterIsSelectable) {
  SEAMLESS_REQUIRE_EGL();
  Renderer r(RenderParams{}, 32, 24);
  EXPECT_EQ(RenderParams{}.fluid_splat, FluidSplat::compute);
  if (!r.uses_compute_splat()) GTEST_SKIP() << "no GL 4.3 compute here";
  r.params().fluid_splat = FluidSplat::raster;
  EXPECT_FALSE(r.uses_compute_splat());
}

}  // namespace
}  // namespace seamless::test

namespace seamless::test {
namespace {

// The full-screen passes (filter, normals, composite) run as compute shaders with the splats: the
// same per-texel functions (ssfr_*.glsl) as the fragment versions, so the same frame. Where the
// filtered depth agrees bit for bit over the 5 x 5 texels a pixel's normal and shading read, the
// colours can differ only through the thickness (fixed point, within 1e-4 m: see thickness_tol):
// Beer-Lambert exp(-25/m T) (the red default) changes by < 2.5e-3 relative (0.64 of a level);
// the refracted sample (at most the path T along a ray bent by at most 1/1.33 sideways) moves by
// < 0.75 f / z 1e-4 m = 0.012 pixel over a wall of one colour whose only gradient is the fluid's
// soft shadow (a few levels per pixel): < 0.1 level. Below one level before rounding: at most 1
// level apart after it.
TEST(RenderSplat, ComputeScreenPassesGiveTheRasterFrame) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(400.f, 79.5f, 59.5f, 160, 120);
  const Block b;
  RenderParams p;
  p.znear = kNear;
  p.fluid_anisotropy = false;  // the raster sprites are spheres
  const Drawn a = draw_with(p, b, K, 2.5f, FluidSplat::raster),
              c = draw_with(p, b, K, 2.5f, FluidSplat::compute);  // wall behind
  if (!c.compute) GTEST_SKIP() << "no GL 4.3 compute here";
  const Pixels ras(a.frame), cmp(c.frame);
  const auto &ras_d = a.fluid.depth, &cmp_d = c.fluid.depth;
  auto same_depth_near = [&](int x, int y) {  // (x, y): window texel
    for (int v = std::max(0, y - 2); v <= std::min(K.height - 1, y + 2); ++v)
      for (int u = std::max(0, x - 2); u <= std::min(K.width - 1, x + 2); ++u)
        if (ras_d[static_cast<std::size_t>(v) * K.width + u] != cmp_d[static_cast<std::size_t>(v) * K.width + u])
          return false;
    return true;
  };
  int fluid = 0, compared = 0;
  for (int v = 0; v < K.height; ++v)
    for (int u = 0; u < K.width; ++u) {
      const int y = K.height - 1 - v;
      fluid += ras_d[static_cast<std::size_t>(y) * K.width + u] > 0.f ? 1 : 0;
      if (!same_depth_near(u, y)) continue;
      ++compared;
      EXPECT_LE(max_diff(ras.at(u, v), cmp.at(u, v)), 1) << "at " << u << "," << v;
    }
  EXPECT_GT(fluid, 2000);
  EXPECT_GT(compared, K.width * K.height * 95 / 100);  // depth ties are rare: nearly all compared
}

}  // namespace
}  // namespace seamless::test

namespace seamless::test {
namespace {
namespace occluders_test {

// A lattice block of side^3 fluid particles (spacing one diameter) turned to show three faces,
// its centre 1.5 m in front of the camera.
struct LatticeBlock {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  float r = 0.01f;
  // jitter: each particle moved by up to this many spacings along each axis (uniform, seeded).
  explicit LatticeBlock(int side, float jitter = 0.f) {
    const mat3 R = rotation(vec3{1.f, 1.f, 0.f}, 0.6f);
    const float c = 0.5f * static_cast<float>(side - 1);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(-jitter, jitter);
    for (int k = 0; k < side; ++k)
      for (int j = 0; j < side; ++j)
        for (int i = 0; i < side; ++i) {
          const vec3 q{i - c + u(rng), j - c + u(rng), k - c + u(rng)};
          x.push_back(R * (2.f * r * q) + vec3{0.f, 0.f, 1.5f});
        }
    ph.assign(x.size(), phase::kFluid);
  }
  DrawList list() const {
    DrawList d;
    d.positions = x, d.phases = ph, d.particle_radius = r;
    return d;
  }
};

struct OccluderRun {
  Renderer::FluidImages fluid;
  Renderer::OccluderCounts counts;
  bool compute = false;
};
OccluderRun draw_block(const LatticeBlock& b, const Intrinsics& K, bool occluders) {
  RenderParams p;
  p.znear = kNear;
  p.filter_iterations = 0;  // the splat's own depth
  p.fluid_occluders = occluders;
  Renderer r(p, K.width, K.height);
  r.draw(b.list(), camera(K));
  return {r.read_fluid_images(), r.fluid_occluder_counts(), r.uses_compute_splat()};
}

}  // namespace occluders_test

// The depth splat with the surface particles first (render.fluid_occluders) against one pass
// over every particle: the minimum of the same depths, whatever their order, so the same image
// bit for bit; the occluders are exactly the particles whose kernel put them at the surface, and
// most of the block's inside is skipped.
TEST(RenderSplat, OccludersFirstGiveTheSameDepthAndSkipTheHidden) {
  SEAMLESS_REQUIRE_EGL();
  using namespace occluders_test;
  const Intrinsics K = intrinsics(300.f, 79.5f, 59.5f, 160, 120);
  const LatticeBlock b(14);
  const OccluderRun one = draw_block(b, K, false), two = draw_block(b, K, true);
  if (!two.compute) GTEST_SKIP() << "no GL 4.3 compute here";
  EXPECT_EQ(one.counts.occluders, 0);
  ASSERT_EQ(one.fluid.depth.size(), two.fluid.depth.size());
  int fluid = 0;
  for (std::size_t i = 0; i < one.fluid.depth.size(); ++i) {
    ASSERT_EQ(std::memcmp(&one.fluid.depth[i], &two.fluid.depth[i], sizeof(float)), 0)
        << "pixel " << i << ": one pass " << one.fluid.depth[i] << ", occluders first " << two.fluid.depth[i];
    fluid += one.fluid.depth[i] > 0.f;
  }
  EXPECT_GT(fluid, 1000);  // the block covers a good part of the image
  // The occluders: the particles with the offset of ssfr_occluders.comp, from the kernels on the CPU.
  RenderParams p;
  const Renderer probe(p, 8, 8);
  const auto sizes = probe.fluid_ellipsoid_sizes(b.r);
  ASSERT_TRUE(sizes.has_value());
  const std::vector<vec4> e = FluidEllipsoids(Device::CPU).compute_host(b.x, b.ph, sizes->radius, sizes->h);
  std::int64_t surface = 0;
  for (std::size_t i = 0; i < b.x.size(); ++i) surface += e[FluidEllipsoids::kVec4s * i + 2].w >= 0.15f;
  // The outer layer of the 14^3 block (14^3 - 12^3 = 1016 particles), and none of the next: h is
  // two spacings, and the layer a particle of the next one lacks lies two spacings away, where the
  // weight 1 - (d/h)^3 is 0, so its neighbourhood is whole and its offset 0 by symmetry.
  EXPECT_EQ(surface, 14 * 14 * 14 - 12 * 12 * 12);
  EXPECT_EQ(two.counts.occluders, surface);
  const std::int64_t others = static_cast<std::int64_t>(b.x.size()) - surface;
  std::printf("occluders %lld, skipped %lld of the other %lld\n", static_cast<long long>(two.counts.occluders),
              static_cast<long long>(two.counts.skipped), static_cast<long long>(others));
  EXPECT_GT(two.counts.skipped, others / 2);
}

// The same with the particles jittered by up to 0.45 spacings: the outer layer is ragged, so
// particles inside show through its gaps and stick out of it in places, and a skip that were not
// sure (a bound above some entry depth) would leave a pixel too deep.
TEST(RenderSplat, OccludersFirstGiveTheSameDepthOfARaggedBlock) {
  SEAMLESS_REQUIRE_EGL();
  using namespace occluders_test;
  const Intrinsics K = intrinsics(300.f, 79.5f, 59.5f, 160, 120);
  const LatticeBlock b(14, 0.45f);
  const OccluderRun one = draw_block(b, K, false), two = draw_block(b, K, true);
  if (!two.compute) GTEST_SKIP() << "no GL 4.3 compute here";
  ASSERT_EQ(one.fluid.depth.size(), two.fluid.depth.size());
  for (std::size_t i = 0; i < one.fluid.depth.size(); ++i)
    ASSERT_EQ(std::memcmp(&one.fluid.depth[i], &two.fluid.depth[i], sizeof(float)), 0)
        << "pixel " << i << ": one pass " << one.fluid.depth[i] << ", occluders first " << two.fluid.depth[i];
  std::printf("ragged: occluders %lld, skipped %lld\n", static_cast<long long>(two.counts.occluders),
              static_cast<long long>(two.counts.skipped));
  EXPECT_GT(two.counts.occluders, 0);
  EXPECT_GT(two.counts.skipped, 0);
}

}  // namespace
}  // namespace seamless::test
