// Shadows in the mesh view, against analytic footprints: a floor mesh (the scan, unlit: its
// colours hold the room's light) under a cube and under a slab of water, the light straight down.
#include <cmath>
#include <numbers>

#include "core/phase.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

// A 4 x 4 m floor at y = 0, one colour, seen from above at an angle.
Mesh floor_scan(uchar3 c) {
  Mesh m;
  m.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  m.normals.assign(4, vec3{0, 1, 0});
  m.colors.assign(4, c);
  m.triangles = {{0, 2, 1}, {0, 3, 2}};
  return m;
}

RenderCamera above() { return RenderCamera::look_at({0.f, 1.0f, 1.3f}, {0.f, 0.f, -0.15f}, {0, 1, 0}, 40.f, 240, 180); }

// Where pixel (u, v)'s ray meets the floor.
vec3 floor_point(const RenderCamera& c, int u, int v) {
  const vec3 d = c.world_T_camera.rotate(c.K.unproject(static_cast<float>(u), static_cast<float>(v), 1.f));
  const vec3 o = c.world_T_camera.t;
  return o + d * (-o.y / d.y);
}

RenderParams down_light() {
  RenderParams p;
  p.light_dir = {0.f, -1.f, 0.f};
  p.shadow_map_size = 1024;
  return p;
}

// A cube floating 0.15 m above the floor. Its shadow straight down is the square |x|, |z| < 0.12;
// the renderer may blur it by tan(light_angle / 2) times the depth below the cube's top (at
// most 0.39 m) plus three texels (minimum filter, bilinear footprint, the rasterised edge; a
// texel is at most the cube's diagonal over the map's inner size). Inside the square shrunk by
// that margin the floor's linear colour is (1 - shadow_strength) of the unshadowed one, within
// one 8-bit level; outside the square grown by it, the same colour as without shadows.
TEST(RenderShadow, MeshViewFloorUnderACube) {
  SEAMLESS_REQUIRE_EGL();
  const RenderParams p = down_light();
  Renderer r(p, 240, 180);
  const uchar3 floor_colour{200, 180, 160};
  r.set_scene_mesh(floor_scan(floor_colour));
  DrawList list;
  RigidDraw cube;
  const float half = 0.12f;
  cube.world_T_body.t = {0.f, 0.15f + half, 0.f};
  cube.half_extents = {half, half, half};
  list.rigids = {cube};
  const RenderCamera cam = above();
  const Pixels bg(r.render(DrawList{}, cam));
  r.params().shadows = false;
  const Pixels off(r.render(list, cam));
  r.params().shadows = true;
  const Pixels on(r.render(list, cam));
  const float margin = std::tan(0.5f * p.light_angle * std::numbers::pi_v<float> / 180.f) * (0.15f + 2 * half) +
                       3.f * 2.f * std::sqrt(3.f) * half / (p.shadow_map_size - 4);
  const float k = p.shadow_strength;
  int umbra = 0, lit = 0;
  for (int v = 0; v < on.h; ++v)
    for (int u = 0; u < on.w; ++u) {
      if (!same(off.at(u, v), bg.at(u, v))) continue;  // the cube
      if (!same(bg.at(u, v), floor_colour)) continue;  // beyond the floor (the unlit floor is its colour)
      const vec3 q = floor_point(cam, u, v);
      const float m = std::max(std::abs(q.x), std::abs(q.z));
      const uchar3 c = on.at(u, v);
      if (m < half - margin) {
        ++umbra;
        for (int i = 0; i < 3; ++i) {
          const std::uint8_t got = (&c.x)[i], was = (&floor_colour.x)[i];
          const float level = linear(got) - linear(static_cast<std::uint8_t>(got - 1));
          EXPECT_NEAR(linear(got), (1.f - k) * linear(was), level) << u << "," << v << " channel " << i;
        }
      } else if (m > half + margin) {
        ++lit;
        EXPECT_TRUE(same(c, floor_colour)) << "shadow outside the footprint at " << u << "," << v;
      }
    }
  EXPECT_GT(umbra, 300);
  EXPECT_GT(lit, 15000);
}

// Water transmits: the shadow of a slab of fluid (12 x 12 particles, 3 layers, 0.15 m above the
// floor) is the light its path in fluid lets through, Beer-Lambert per channel, not black. Under
// the slab's interior (one sphere radius in from its edge) the test sums, at each floor point, the
// chords of the enlarged spheres straight above it over their volume fraction (as the renderer's
// splat does) and expects the linear colour 1 - strength (1 - exp(-absorption T)) of the lit one.
// The mean over the interior must agree within 0.03 per channel: the map samples the path at
// texel centres a quarter sphere radius apart and interpolates, and the floor points of one pixel
// spread over about a texel; averaged over a few hundred pixels these differences are below 1 %
// of the expected ratio (about 0.5 to 0.85 here), the 8-bit output adds 1 / 255 at most. An
// opaque shadow would give 1 - strength = 0.5 in every channel: at least 0.1 below the blue
// channel's expectation here.
TEST(RenderShadow, WaterShadowIsTintedByBeerLambert) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p = down_light();
  Renderer r(p, 240, 180);
  const uchar3 floor_colour{220, 220, 220};
  r.set_scene_mesh(floor_scan(floor_colour));
  const float rad = 0.02f;
  const int n = 12, layers = 3;
  std::vector<vec3> x;
  for (int k = 0; k < layers; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        x.push_back({(i - 0.5f * (n - 1)) * 2 * rad, 0.15f + 2 * rad * k, (j - 0.5f * (n - 1)) * 2 * rad});
  const std::vector<std::uint32_t> ph(x.size(), phase::kFluid);
  DrawList list;
  list.positions = x, list.phases = ph, list.particle_radius = rad;
  const RenderCamera cam = above();
  const Pixels on(r.render(list, cam));
  const Renderer::FluidImages fluid = r.read_fluid_images();  // rows bottom to top
  const float s = p.fluid_radius_scale, R = s * rad, scale = 6.f / (std::numbers::pi_v<float> * s * s * s);
  const float half = n * rad - R;  // interior: the column centres' extent
  vec3 sum_got{0, 0, 0}, sum_want{0, 0, 0};
  int count = 0;
  for (int v = 0; v < on.h; ++v)
    for (int u = 0; u < on.w; ++u) {
      if (fluid.depth[static_cast<std::size_t>(on.h - 1 - v) * on.w + u] > 0.f) continue;  // the slab itself
      const vec3 q = floor_point(cam, u, v);
      if (std::abs(q.x) > half || std::abs(q.z) > half) continue;
      float T = 0.f;
      for (const vec3& c : x) {
        const float d2 = (q.x - c.x) * (q.x - c.x) + (q.z - c.z) * (q.z - c.z);
        if (d2 < R * R) T += 2.f * std::sqrt(R * R - d2) * scale;
      }
      const uchar3 c = on.at(u, v);
      for (int i = 0; i < 3; ++i) {
        (&sum_got.x)[i] += linear((&c.x)[i]) / linear((&floor_colour.x)[i]);
        (&sum_want.x)[i] += 1.f - p.shadow_strength * (1.f - std::exp(-(&p.absorption.x)[i] * T));
      }
      ++count;
    }
  ASSERT_GT(count, 300);
  const vec3 got = sum_got * (1.f / count), want = sum_want * (1.f / count);
  std::printf("water shadow, linear ratio to lit: got (%.3f %.3f %.3f), Beer-Lambert (%.3f %.3f %.3f)\n", got.x, got.y,
              got.z, want.x, want.y, want.z);
  for (int i = 0; i < 3; ++i) EXPECT_NEAR((&got.x)[i], (&want.x)[i], 0.03f) << "channel " << i;
  EXPECT_GT(want.z, 1.f - p.shadow_strength + 0.1f) << "the scene does not tell water from an opaque caster";
}

// A layer of water one particle thick, spread at 1.5 diameters (13 x 13 particles, 0.15 m above
// the floor), casts one even shadow with anisotropic kernels: the discs of 2.4 radii overlap
// where the 1.5-radius spheres leave a hole at every lattice diagonal (2.1 radii from the nearest
// particle; docs/RENDERING.md, anisotropic kernels). The splats' path in fluid is the particles'
// volume (a cube of one diameter each, 8 r^3, whatever their shape), so under the interior (one
// spacing in from the outer columns) the mean path is 8 r^3 / spacing^2 = 8 r / 9 and the floor's
// linear colour 1 - strength (1 - exp(-absorption 8 r / 9)) of the lit one: the mean must agree
// within 0.03 (as in the test above). No pixel may be a quarter of the way from there to the lit
// floor: where a hole lets the light through, the floor is lit. A nearly point-like light (0.5
// degrees: a penumbra of 1.3 mm here, against holes of ~1 cm) keeps the spheres' holes visible,
// which the same check must find (it can fail). Pixels: the floor the camera sees past the
// layer's near edge.
TEST(RenderShadow, ASpreadLayerCastsOneEvenShadow) {
  SEAMLESS_REQUIRE_EGL();
  const float rad = 0.02f, spacing = 3.f * rad;
  const int n = 13;
  std::vector<vec3> x;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.push_back({(i - 0.5f * (n - 1)) * spacing, 0.15f, (j - 0.5f * (n - 1)) * spacing});
  const std::vector<std::uint32_t> ph(x.size(), phase::kFluid);
  DrawList list;
  list.positions = x, list.phases = ph, list.particle_radius = rad;
  const uchar3 floor_colour{220, 220, 220};
  const float half = (0.5f * (n - 1) - 1.f) * spacing, absorption = 40.f;  // well above 8-bit steps
  RenderParams p = down_light();
  p.light_angle = 0.5f;
  p.absorption = {absorption, absorption, absorption};
  const float want = 1.f - p.shadow_strength * (1.f - std::exp(-absorption * 8.f * rad / 9.f));
  const float hole = want + 0.25f * (1.f - want);
  const RenderCamera cam = above();
  struct Seen {
    int pixels = 0;
    float mean = 0.f, brightest = 0.f;
  };
  auto floor_under = [&](bool aniso) {
    p.fluid_anisotropy = aniso;
    Renderer r(p, 240, 180);
    r.set_scene_mesh(floor_scan(floor_colour));
    const Pixels img(r.render(list, cam));
    const Renderer::FluidImages fluid = r.read_fluid_images();  // rows bottom to top
    Seen s;
    for (int v = 0; v < img.h; ++v)
      for (int u = 0; u < img.w; ++u) {
        if (fluid.depth[static_cast<std::size_t>(img.h - 1 - v) * img.w + u] > 0.f) continue;  // the layer
        const vec3 q = floor_point(cam, u, v);
        if (std::abs(q.x) > half || std::abs(q.z) > half) continue;
        const float ratio = linear(img.at(u, v).x) / linear(floor_colour.x);
        ++s.pixels, s.mean += ratio, s.brightest = std::max(s.brightest, ratio);
      }
    s.mean /= std::max(s.pixels, 1);
    return s;
  };
  const Seen spheres = floor_under(false), discs = floor_under(true);
  std::printf(
      "floor under the layer, linear ratio to lit (Beer-Lambert %.3f): spheres mean %.3f brightest %.3f, "
      "ellipsoids mean %.3f brightest %.3f (%d pixels)\n",
      want, spheres.mean, spheres.brightest, discs.mean, discs.brightest, discs.pixels);
  ASSERT_GT(discs.pixels, 300);
  EXPECT_NEAR(discs.mean, want, 0.03f);
  EXPECT_LT(discs.brightest, hole);
  EXPECT_GT(spheres.brightest, hole);
}

// Particles drawn as spheres (render.fluid: particles) are opaque casters: a slab of them 0.15 m
// above the floor leaves the floor under its interior at (1 - shadow_strength) of its linear
// colour, as a cube does (the margin as there: penumbra and texels), not the water's tint.
TEST(RenderShadow, ParticlesDrawnAsSpheresCastAnOpaqueShadow) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p = down_light();
  p.fluid = FluidDraw::particles;
  Renderer r(p, 240, 180);
  const uchar3 floor_colour{200, 180, 160};
  r.set_scene_mesh(floor_scan(floor_colour));
  const float rad = 0.02f;
  const int n = 12;
  std::vector<vec3> x;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.push_back({(i - 0.5f * (n - 1)) * 2 * rad, 0.15f, (j - 0.5f * (n - 1)) * 2 * rad});
  const std::vector<std::uint32_t> ph(x.size(), phase::kFluid);
  DrawList list;
  list.positions = x, list.phases = ph, list.particle_radius = rad;
  const RenderCamera cam = above();
  r.params().shadows = false;
  const Pixels off(r.render(list, cam));
  r.params().shadows = true;
  const Pixels on(r.render(list, cam));
  const float half = n * rad;
  const float margin = std::tan(0.5f * p.light_angle * std::numbers::pi_v<float> / 180.f) * (0.15f + rad) +
                       3.f * 2.f * std::sqrt(2.f) * half / (p.shadow_map_size - 4) + rad;
  int umbra = 0;
  for (int v = 0; v < on.h; ++v)
    for (int u = 0; u < on.w; ++u) {
      if (!same(off.at(u, v), floor_colour)) continue;  // the spheres, or beyond the floor
      const vec3 q = floor_point(cam, u, v);
      if (std::max(std::abs(q.x), std::abs(q.z)) > half - margin) continue;
      ++umbra;
      const uchar3 c = on.at(u, v);
      for (int i = 0; i < 3; ++i) {
        const std::uint8_t got = (&c.x)[i], was = (&floor_colour.x)[i];
        const float level = linear(got) - linear(static_cast<std::uint8_t>(got - 1));
        EXPECT_NEAR(linear(got), (1.f - p.shadow_strength) * linear(was), level) << u << "," << v << " channel " << i;
      }
    }
  EXPECT_GT(umbra, 100);
}
}  // namespace
}  // namespace seamless::test
