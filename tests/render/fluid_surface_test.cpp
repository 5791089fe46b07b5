// The fluid's surface and its shading against analytic truth, on small frames (each test renders a
// few 200 x 150 frames on llvmpipe):
//   - gap fill: a layer of particles spread over a plane (the spacing a spill leaves) gives one
//     surface with no holes, between the spheres' fronts and their centres; without the fill it
//     has holes (what the fill is for);
//   - no bridge and no bleeding across a depth step: two layers 0.3 m apart in depth keep the gap
//     between them empty and each keeps its own depth;
//   - the gap fill respects the scene: a real bar in front of the layer is not covered;
//   - Beer-Lambert: the refracted background's linear colour is exp(-absorption T) of what is
//     behind, T the slab's thickness;
//   - wetting: the same slab resting on a surface darkens it by Lekner & Dorf's factor, not in the air;
//   - anisotropic kernels: a tilted spread layer is one sheet without any gap fill, within the slab
//     its flattened ellipsoids span, and its normals are the plane's within a bound derived from
//     the ellipsoids' shape;
//   - a puddle seen at a grazing angle (a table 15 cm below the camera) is as smooth as one seen
//     face-on: its normals are the plane's within the same kind of bound (no bands from the depth
//     filter's range), and a blob of water in front of it stays apart from it; its front rim,
//     the particles jittered, has no streaks across it;
//   - a lone particle is drawn as a drop of its own radius, with a sphere's normals; lying on a
//     surface, as a sessile drop of its volume.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "core/phase.hpp"
#include "physics/fluid_ellipsoids.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

constexpr int kW = 200, kH = 150;
constexpr float kF = 300.f;

Intrinsics small_K() { return intrinsics(kF, 99.5f, 74.5f, kW, kH); }

// Particles of radius r on a square lattice of spacing s in the plane z = const facing the
// camera, centred at (cx, cy): n x n of them.
void layer(std::vector<vec3>& x, float cx, float cy, float z, int n, float s) {
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) x.push_back({cx + (i - 0.5f * (n - 1)) * s, cy + (j - 0.5f * (n - 1)) * s, z});
}

DrawList fluid_list(const std::vector<vec3>& x, std::vector<std::uint32_t>& ph, float r) {
  ph.assign(x.size(), phase::kFluid);
  DrawList d;
  d.positions = x, d.phases = ph, d.particle_radius = r;
  return d;
}

// sRGB-encoded 8-bit value to linear (IEC 61966-2-1), as color.glsl decodes.
vec3 linear(uchar3 c) {
  auto f = [](std::uint8_t b) {
    const float v = b / 255.f;
    return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
  };
  return {f(c.x), f(c.y), f(c.z)};
}

// Filtered eye depth at image pixel (u, v) (the read-back rows run bottom to top).
float depth_at(const Renderer::FluidImages& f, int u, int v) {
  return f.depth[static_cast<std::size_t>(f.h - 1 - v) * f.w + u];
}

// A fluid depth's lone-drop tag (camera.glsl, with_drop_tag): its least significant mantissa bit
// for a drop, the next for a drop lying flat.
std::uint32_t drop_tag(float z) {
  std::uint32_t b = 0;
  std::memcpy(&b, &z, sizeof b);
  return z > 0.f ? b & 3u : 0u;
}

// Sphere splats: the gap fill and the shading are checked on their own (anisotropic kernels, which
// flatten a spread layer before the fill sees it, have their own tests below).
RenderParams surface_params() {
  RenderParams p;
  p.fluid_anisotropy = false;
  p.shadows = false;
  p.background = {0.8f, 0.8f, 0.8f};
  return p;
}

// A uniform grey table facing the camera: the Kinect frame (colour and recorded depth) that the
// shading tests put water on.
const uchar3 kTableGrey{150, 150, 150};
constexpr float kTableZ = 1.2f;
std::vector<uchar3> table_rgb() { return std::vector<uchar3>(static_cast<std::size_t>(kW) * kH, kTableGrey); }
std::vector<float> table_depth() { return std::vector<float>(static_cast<std::size_t>(kW) * kH, kTableZ); }

// A layer spread to spacing 3 r (spheres of the default 1.5 r just touch along the lattice; the
// holes at the lattice's diagonals, 2.12 r from each centre, are open): inside the layer's
// projection, shrunk by one spacing, every pixel has a depth after the filter, and that depth lies
// between the spheres' fronts (z - 1.5 r, less one window-depth step) and the centre plane z: the
// filter averages the spheres' caps and the fill's interpolations, both within that range.
// Without the fill the same pixels have holes.
TEST(RenderFluidSurface, GapFillClosesASpreadLayer) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const float r = 0.01f, z = 1.f, s = 3.f * r;
  std::vector<vec3> x;
  layer(x, 0.f, 0.f, z, 9, s);
  std::vector<std::uint32_t> ph;
  const DrawList list = fluid_list(x, ph, r);
  const float half = 4.f * s - s;  // the layer's half-width (centres), shrunk by one spacing
  const int u0 = static_cast<int>(std::ceil(K.cx - kF * half / z)), u1 = static_cast<int>(K.cx + kF * half / z);
  const int v0 = static_cast<int>(std::ceil(K.cy - kF * half / z)), v1 = static_cast<int>(K.cy + kF * half / z);
  auto holes_and_range = [&](float gap_fill, float& lo, float& hi) {
    RenderParams p = surface_params();
    p.fluid_gap_fill = gap_fill;
    Renderer rd(p, kW, kH);
    rd.draw(list, camera(K));
    const Renderer::FluidImages f = rd.read_fluid_images();
    int holes = 0;
    lo = 1e9f, hi = -1e9f;
    for (int v = v0; v <= v1; ++v)
      for (int u = u0; u <= u1; ++u) {
        const float d = depth_at(f, u, v);
        if (d <= 0.f) ++holes;
        else lo = std::min(lo, d), hi = std::max(hi, d);
      }
    return holes;
  };
  float lo = 0.f, hi = 0.f;
  const int holes_off = holes_and_range(0.f, lo, hi);
  const int holes = holes_and_range(RenderParams{}.fluid_gap_fill, lo, hi);
  std::printf("pixels %d; holes without the fill %d, with it %d; depth %.4f..%.4f m\n", (u1 - u0 + 1) * (v1 - v0 + 1),
              holes_off, holes, lo, hi);
  EXPECT_GT(holes_off, 20) << "the layer should have holes without the fill (the test's premise)";
  EXPECT_EQ(holes, 0);
  EXPECT_GE(lo, z - 1.5f * r - 1e-3f);
  EXPECT_LE(hi, z + 1e-4f);
}

// Two spread layers side by side, the right one 0.3 m further: 2 cm of empty space between their
// outermost spheres (about 5 pixels, within the fill's reach of 4 radii at these depths), but
// their depths differ by far more than the range mu plus that span: the gap stays empty, and
// neither layer's depth is pulled towards the other beyond what the narrow-range filter allows
// (each within its own spheres' fronts and centre plane; the far one's edge up to mu nearer).
TEST(RenderFluidSurface, NoBridgeOrBleedingAcrossADepthStep) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const float r = 0.01f, s = 3.f * r, rs = 1.5f * r;
  const float zn = 1.f, zf = 1.3f;
  // Right edge of the near layer's spheres at x = -0.01; left edge of the far layer's at +0.01.
  const float xn = -0.01f - rs - 2.f * s, xf = 0.01f + rs + 2.f * s;
  std::vector<vec3> x;
  layer(x, xn, 0.f, zn, 5, s);
  layer(x, xf, 0.f, zf, 5, s);
  std::vector<std::uint32_t> ph;
  Renderer rd(surface_params(), kW, kH);
  rd.draw(fluid_list(x, ph, r), camera(K));
  const Renderer::FluidImages f = rd.read_fluid_images();
  const int v = static_cast<int>(K.cy);
  // Pixels whose rays pass strictly between the two layers' sphere bounds (one pixel margin).
  const int g0 = static_cast<int>(std::ceil(K.cx + kF * -0.01f / zn)) + 1;
  const int g1 = static_cast<int>(K.cx + kF * 0.01f / zf) - 1;
  ASSERT_GT(g1, g0);
  for (int u = g0; u <= g1; ++u) EXPECT_EQ(depth_at(f, u, v), 0.f) << "bridged at u = " << u;
  int near = 0, far = 0;
  for (int u = 0; u < kW; ++u) {
    const float d = depth_at(f, u, v);
    if (d <= 0.f) continue;
    const bool is_near = u < g0;
    (is_near ? near : far)++;
    // The narrow-range filter leaves samples behind the centre by more than mu out and clamps
    // those in front to z - mu: a far pixel next to the near layer moves forward by at most mu,
    // a near pixel not at all (0.3 m would be bleeding).
    const float z = is_near ? zn : zf, mu = is_near ? 0.f : 3.f * RenderParams{}.filter_depth_sigma * r;
    EXPECT_GE(d, z - rs - mu - 1e-3f) << "bled at u = " << u;
    EXPECT_LE(d, z + 1e-4f) << "bled at u = " << u;
  }
  EXPECT_GT(near, 20);
  EXPECT_GT(far, 15);
}

// The Kinect view of a flat surface at 1.2 m with a bar 5 pixels wide at 0.8 m in front of it
// (depth image), and a spread layer at 1 m behind the bar: the bar hides the spheres behind it,
// and the fill, whose two sides agree, must not cover the bar either (the scene is in front).
TEST(RenderFluidSurface, GapFillLeavesTheSceneInFront) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  std::vector<uchar3> rgb(static_cast<std::size_t>(kW) * kH, uchar3{200, 200, 200});
  std::vector<float> depth(rgb.size(), 1.2f);
  const int b0 = 98, b1 = 102;
  for (int v = 0; v < kH; ++v)
    for (int u = b0; u <= b1; ++u) depth[static_cast<std::size_t>(v) * kW + u] = 0.8f;
  RenderParams p = surface_params();
  p.view = RenderView::kinect;
  Renderer rd(p, kW, kH);
  rd.set_kinect_view(Image<uchar3>::from_host(rgb, kW, kH, Device::CPU),
                     Image<float>::from_host(depth, kW, kH, Device::CPU), K, SE3::identity());
  const float r = 0.01f;
  std::vector<vec3> x;
  layer(x, 0.f, 0.f, 1.f, 9, 3.f * r);
  std::vector<std::uint32_t> ph;
  rd.draw(fluid_list(x, ph, r), RenderCamera{});
  const Renderer::FluidImages f = rd.read_fluid_images();
  int fluid_beside = 0;
  for (int v = 60; v <= 90; ++v) {
    for (int u = b0; u <= b1; ++u) EXPECT_EQ(depth_at(f, u, v), 0.f) << "fluid over the bar at " << u << "," << v;
    fluid_beside += depth_at(f, b0 - 3, v) > 0.f && depth_at(f, b1 + 3, v) > 0.f ? 1 : 0;
  }
  EXPECT_GT(fluid_beside, 25) << "the test needs fluid on both sides of the bar";
}

// A slab of fluid (a lattice of one diameter, the spheres' thickness scaled to a path in fluid)
// in front of a uniform Kinect image, its back 0.2 m before the measured surface (in the air: not
// wet), then resting on it (wet). Face-on, so the depth of water h is the thickness T (n layers of
// 2 r) and the refracted view ray crosses it over T. Refraction stage in linear units, mean over
// the slab's centre:
//   in the air: what is behind times exp(-absorption T) (Beer-Lambert up the view ray);
//   resting:    also the light's way down, exp(-absorption T / mu_d) (mu_d = 0.83, the downwelling
//               mean cosine; shadows are off, so all of the light), and Lekner & Dorf's wet factor
//               (1 - R_e) / (n^2 (1 - a R_i exp(-4 absorption T))) with its internal reflections
//               absorbed on their round trip, a the image's linear value (the albedo it stands for).
// Tolerances: T is a sum of sphere chords over their volume fraction; across the slab's centre it
// scatters about the true depth by a fraction of a radius, so both are checked within the range
// T +- r gives, plus one 8-bit level (stage images: a level in 60-200).
TEST(RenderFluidSurface, BeerLambertAndWetting) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const uchar3 grey = kTableGrey;
  const float z_surface = kTableZ;
  std::vector<uchar3> rgb = table_rgb();
  std::vector<float> depth = table_depth();
  RenderParams p = surface_params();
  p.view = RenderView::kinect;
  p.stage_images = true;
  p.light_intensity = 0.f;
  p.absorption = {20.f, 8.f, 2.f};
  const float r = 0.01f, d = 2.f * r;
  const int layers = 4;
  const float T = layers * d;
  auto refraction = [&](float back) {  // mean linear refraction over the slab's centre
    Renderer rd(p, kW, kH);
    rd.set_kinect_view(Image<uchar3>::from_host(rgb, kW, kH, Device::CPU),
                       Image<float>::from_host(depth, kW, kH, Device::CPU), K, SE3::identity());
    std::vector<vec3> x;
    // The back layer's spheres (1.5 r as drawn) touch `back`: none is cut by the surface, so the
    // thickness is the same resting or in the air.
    for (int k = 0; k < layers; ++k) layer(x, 0.f, 0.f, back - 1.5f * r - k * d, 12, d);
    std::vector<std::uint32_t> ph;
    rd.draw(fluid_list(x, ph, r), RenderCamera{});
    const StageImage* st = nullptr;
    for (const StageImage& s : rd.stage_images())
      if (s.name == "6_refraction") st = &s;
    EXPECT_NE(st, nullptr);
    if (!st) return vec3{0, 0, 0};
    const Pixels im(st->image);
    vec3 sum{0, 0, 0};
    int n = 0;
    for (int v = 65; v < 85; ++v)
      for (int u = 90; u < 110; ++u) {
        sum = sum + linear(im.at(u, v));
        ++n;
      }
    return sum * (1.f / static_cast<float>(n));
  };
  const vec3 behind = linear(grey);
  const vec3 dry = refraction(z_surface - 0.2f);
  const vec3 wet = refraction(z_surface);
  const float a[3] = {p.absorption.x, p.absorption.y, p.absorption.z};
  const float n2 = p.ior * p.ior, Re = p.fresnel_f0 + (1.f - p.fresnel_f0) / 21.f, Ri = 1.f - (1.f - Re) / n2;
  const float mu_d = 0.5f / n2 / (1.f - std::sqrt(1.f - 1.f / n2));
  // wet / dry for a depth of water h, channel c.
  auto wet_ratio = [&](int c, float h) {
    return std::exp(-a[c] * h / mu_d) * (1.f - Re) / (n2 * (1.f - behind.x * Ri * std::exp(-4.f * a[c] * h)));
  };
  for (int c = 0; c < 3; ++c) {
    const float got = (&dry.x)[c] / (&behind.x)[c];
    const float ratio = (&wet.x)[c] / (&dry.x)[c];
    std::printf(
        "channel %d: dry transmittance %.3f (exp(-a T) %.3f, range %.3f..%.3f); wet/dry %.3f (expected %.3f, "
        "range %.3f..%.3f)\n",
        c, got, std::exp(-a[c] * T), std::exp(-a[c] * (T + r)), std::exp(-a[c] * (T - r)), ratio, wet_ratio(c, T),
        wet_ratio(c, T + r), wet_ratio(c, T - r));
    EXPECT_GE(got, std::exp(-a[c] * (T + r)) - 0.01f);
    EXPECT_LE(got, std::exp(-a[c] * (T - r)) + 0.01f);
    // One 8-bit level of the wet stage (linear, at its value) over the dry value, as a ratio.
    const float level = 1.f / (255.f * (&dry.x)[c]);
    EXPECT_GE(ratio, wet_ratio(c, T + r) - level);
    EXPECT_LE(ratio, wet_ratio(c, T - r) + level);
  }
}

// Water resting on a measured surface, half of it over pixels without recorded depth (a Kinect
// hole, depth 0): a hole is not an occluder, so the water is drawn there, and what the camera saw
// there has the image's colour at an unmeasured depth, not infinitely far. The frame over the hole
// must look like the frame over the measured half: the same uniform image, the same slab (the
// lattice is symmetric about the image centre, so the two halves cover the same sphere pattern
// mirrored). Taken as infinitely far, the hole's pixels counted the water as hanging in the air
// (not wet: 1 / 0.62 times brighter, and the light's way down not absorbed) and ran the refracted
// ray through the whole thickness. Tolerance: 2 % of each channel's linear value (a few 8-bit levels
// at these values; the wet factor alone is a 38 % difference).
TEST(RenderFluidSurface, WaterOverADepthHoleLooksLikeTheWaterAroundIt) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const float z_surface = kTableZ;
  std::vector<uchar3> rgb = table_rgb();
  std::vector<float> depth = table_depth();
  const int hole_u0 = 100;  // the hole: every pixel right of the image centre
  for (int v = 0; v < kH; ++v)
    for (int u = hole_u0; u < kW; ++u) depth[static_cast<std::size_t>(v) * kW + u] = 0.f;
  RenderParams p = surface_params();
  p.view = RenderView::kinect;
  p.light_intensity = 0.f;
  p.absorption = {4.f, 2.f, 1.f};  // linear values 0.05-0.15 over 8 cm: 8-bit steps under 1 %
  const float r = 0.01f, d = 2.f * r;
  Renderer rd(p, kW, kH);
  rd.set_kinect_view(Image<uchar3>::from_host(rgb, kW, kH, Device::CPU),
                     Image<float>::from_host(depth, kW, kH, Device::CPU), K, SE3::identity());
  std::vector<vec3> x;
  for (int k = 0; k < 4; ++k) layer(x, 0.f, 0.f, z_surface - 1.5f * r - k * d, 12, d);
  std::vector<std::uint32_t> ph;
  const Pixels im(rd.render(fluid_list(x, ph, r), RenderCamera{}));
  // Mean linear colour over columns [u0, u1] of rows 60-90 (inside the slab, which spans about
  // u 68-131 and v 43-106, and 4 or more pixels from the hole's edge and the slab's rim).
  auto mean = [&](int u0, int u1) {
    vec3 sum{0, 0, 0};
    int n = 0;
    for (int v = 60; v <= 90; ++v)
      for (int u = u0; u <= u1; ++u) sum = sum + linear(im.at(u, v)), ++n;
    return sum * (1.f / static_cast<float>(n));
  };
  const vec3 measured = mean(80, 95), hole = mean(104, 119);
  for (int c = 0; c < 3; ++c) {
    std::printf("channel %d: over measured depth %.4f, over the hole %.4f\n", c, (&measured.x)[c], (&hole.x)[c]);
    EXPECT_NEAR((&hole.x)[c], (&measured.x)[c], 0.02f * (&measured.x)[c]);
  }
}

// A square n x n layer of spacing s in the plane through c spanned by ex and ey (unit, orthogonal).
struct Plane {
  vec3 c, ex, ey, n;  // n: ex x ey, towards the camera
  float s;
  int count;
  std::vector<vec3> particles() const {
    std::vector<vec3> x;
    for (int j = 0; j < count; ++j)
      for (int i = 0; i < count; ++i)
        x.push_back(c + ex * ((i - 0.5f * (count - 1)) * s) + ey * ((j - 0.5f * (count - 1)) * s));
    return x;
  }
  // Where pixel (u, v)'s ray meets the plane, in the plane's coordinates (a along ex, b along ey),
  // and the ray's depth there.
  void hit(const Intrinsics& K, int u, int v, float& a, float& b, float& z) const {
    const vec3 d{(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.f};
    z = dot(n, c) / dot(n, d);
    const vec3 q = d * z - c;
    a = dot(q, ex), b = dot(q, ey);
  }
};

// A desk-like layer: 13 x 13 particles of radius r = 1 cm spread to spacing 3 r, 1 m away, its
// normal tilted 20 degrees from the view axis (about x).
Plane tilted_layer() {
  const float t = 20.f * 3.14159265f / 180.f, r = 0.01f;
  Plane p;
  p.c = {0.f, 0.f, 1.f};
  p.ex = {1.f, 0.f, 0.f};
  p.ey = {0.f, std::cos(t), std::sin(t)};
  p.n = {0.f, std::sin(t), -std::cos(t)};
  p.s = 3.f * r;
  p.count = 13;
  return p;
}

// Anisotropic kernels (Yu & Turk 2013) on a spread layer, the splats' depth as drawn (no gap fill,
// no filter): every neighbourhood
// is planar, so each ellipsoid has its shortest axis along the plane's normal, at 1/4 of its
// longest (the clamp), and the volume of the 1.5 r sphere. An interior particle's neighbourhood is
// isotropic in the plane: axes (A, A, A/4) with A^3 / 4 = (1.5 r)^3, A = 4^(1/3) 1.5 r = 2.38 r,
// which covers the lattice's holes (s / sqrt(2) = 2.12 r from the centres) where the spheres
// (1.5 r) leave them open. So inside the layer's projection shrunk by one spacing there is no
// hole, and every depth lies in the slab the ellipsoids span: the shortest axis is at most
// 4^(-1/3) 1.5 r = 0.94 r for any planar neighbourhood (rim particles, less isotropic in the
// plane, are thicker than the interior's A / 4 = 0.6 r), so within [plane - 0.94 r, plane] along
// the normal.
TEST(RenderFluidSurface, AnisotropicKernelsMakeASpreadLayerOneSheet) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const Plane pl = tilted_layer();
  const float r = 0.01f;
  const std::vector<vec3> x = pl.particles();
  std::vector<std::uint32_t> ph;
  const DrawList list = fluid_list(x, ph, r);
  const float half = 0.5f * (pl.count - 1) * pl.s - pl.s;
  const float slab = std::pow(4.f, -1.f / 3.f) * 1.5f * r;
  auto holes = [&](bool aniso, float& worst) {
    RenderParams p = surface_params();
    p.fluid_gap_fill = 0.f;
    p.filter_iterations = 0;  // the splats' own depth
    p.fluid_anisotropy = aniso;
    Renderer rd(p, kW, kH);
    rd.draw(list, camera(K));
    EXPECT_TRUE(rd.uses_compute_splat());
    const Renderer::FluidImages f = rd.read_fluid_images();
    int n = 0, inside = 0;
    worst = 0.f;
    for (int v = 0; v < kH; ++v)
      for (int u = 0; u < kW; ++u) {
        float a, b, z;
        pl.hit(K, u, v, a, b, z);
        if (std::abs(a) > half || std::abs(b) > half) continue;
        ++inside;
        const float d = depth_at(f, u, v);
        if (d <= 0.f) {
          ++n;
          continue;
        }
        // Distance of the depth's point in front of the plane, along the normal: (z - d) times
        // the ray's component along n per unit depth.
        const vec3 ray{(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.f};
        const float front = (z - d) * -dot(pl.n, ray);
        worst = std::max(worst, std::max(front - slab, -front));
      }
    EXPECT_GT(inside, 1000);
    return n;
  };
  float worst_spheres = 0.f, worst = 0.f;
  const int holes_spheres = holes(false, worst_spheres);
  const int holes_aniso = holes(true, worst);
  std::printf("holes with spheres %d, with anisotropic kernels %d; depth outside the slab by %.2f mm at most\n",
              holes_spheres, holes_aniso, worst * 1e3f);
  EXPECT_GT(holes_spheres, 50) << "spheres should leave holes in this layer (the test's premise)";
  EXPECT_EQ(holes_aniso, 0);
  EXPECT_LE(worst, 2e-4f);  // R32F depths at 1 m: well under 0.2 mm
}

// The angle in degrees between normal image im's normal at (u, v) and n.
float normal_off_plane(const Pixels& im, int u, int v, vec3 n) {
  const uchar3 q = im.at(u, v);
  vec3 nn{q.x / 127.5f - 1.f, q.y / 127.5f - 1.f, q.z / 127.5f - 1.f};
  nn = nn * (1.f / std::sqrt(dot(nn, nn)));
  return std::acos(std::clamp(dot(nn, n), -1.f, 1.f)) * 180.f / 3.14159265f;
}

// The steepest slope, in degrees, of the upper envelope of a layer of interior discs (A, A, A / 4),
// A = 4^(1/3) 1.5 r, at lattice spacing s: every point is within rho = s / sqrt(2) of a centre,
// where the cap's slope is (1/4) (rho / A) / sqrt(1 - (rho / A)^2); plus 0.5 degree for the 8-bit
// normal image.
float disc_envelope_bound(float r, float s) {
  const float A = std::cbrt(4.f) * 1.5f * r, rho = s / std::sqrt(2.f);
  const float slope = 0.25f * (rho / A) / std::sqrt(1.f - (rho / A) * (rho / A));
  return std::atan(slope) * 180.f / 3.14159265f + 0.5f;
}

// The normals stage (3_normals) of particles x of radius r drawn with the anisotropic kernels
// through camera K at w x h (compute splats).
Pixels anisotropic_normals(const std::vector<vec3>& x, float r, const Intrinsics& K, int w, int h) {
  std::vector<std::uint32_t> ph;
  RenderParams p = surface_params();
  p.fluid_anisotropy = true;
  p.stage_images = true;
  Renderer rd(p, w, h);
  rd.draw(fluid_list(x, ph, r), camera(K));
  EXPECT_TRUE(rd.uses_compute_splat());
  for (const StageImage& s : rd.stage_images())
    if (s.name == "3_normals") return Pixels(s.image);
  ADD_FAILURE() << "no normals stage";
  return Pixels(Image<uchar3>(w, h, Device::CPU));
}

// The same layer with the default surface (anisotropic kernels, gap fill, narrow-range filter):
// its normals are the plane's within the slope of the ellipsoids' upper envelope. Interior
// particles are discs (A, A, c) = (2.38 r, 2.38 r, 0.6 r); the envelope is, at each point, the cap
// of the nearest centre, at most s / sqrt(2) = 2.12 r from it, where the cap's slope is
// (c / A) (rho / A) / sqrt(1 - (rho / A)^2) = 0.25 * 0.891 / 0.454 = 0.49: 26 degrees at most.
// Away from the layer's rim by the filter's half-width (6 r) the filter is a normalised
// non-negative average (the layer's depth span over the filter, 6 r tan 20 deg + 0.6 r, is under
// the narrow range mu = 3 r: no sample is left out or clamped), which cannot steepen a surface.
// The 8-bit normal image adds at most 0.5 degree.
TEST(RenderFluidSurface, AnisotropicSheetHasThePlanesNormal) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const Plane pl = tilted_layer();
  const float r = 0.01f;
  const Pixels im = anisotropic_normals(pl.particles(), r, K, kW, kH);
  const float inner = 0.5f * (pl.count - 1) * pl.s - pl.s - 6.f * r;
  const float bound = disc_envelope_bound(r, pl.s);
  float worst = 0.f, sum = 0.f;
  int n = 0;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      float a, b, z;
      pl.hit(K, u, v, a, b, z);
      if (std::abs(a) > inner || std::abs(b) > inner) continue;
      const float deg = normal_off_plane(im, u, v, pl.n);
      worst = std::max(worst, deg), sum += deg, ++n;
    }
  std::printf("%d pixels: normal off the plane's by %.2f degrees on average, %.2f at most (bound %.1f)\n", n,
              sum / std::max(n, 1), worst, bound);
  EXPECT_GT(n, 500);
  EXPECT_LE(worst, bound);
}

// A puddle on a table seen from 15 cm above it, as the Kinect config sees its table: a Kinect
// frame (640 x 480, f = 525), the table the plane y = 0.15 (camera y points down), one layer of
// particles of radius r = 1 cm resting on it (centres r above it) at the spacing of water at rest
// (2 r), 18 x 18 of them from 0.5 to 0.85 m ahead. At 0.6 m the depth of the surface changes by
// z^2 / (f h) = 4.6 mm from one image row to the next: the narrow range mu (3 r) spans 6.5 rows
// of the depth filter's window (6 r, 24 pixels at most each side).
constexpr int kGW = 640, kGH = 480;
constexpr float kGF = 525.f;
Intrinsics grazing_K() { return intrinsics(kGF, 319.5f, 239.5f, kGW, kGH); }

Plane grazing_puddle() {
  const float r = 0.01f;
  Plane p;
  p.c = {0.f, 0.15f - r, 0.675f};
  p.ex = {1.f, 0.f, 0.f};
  p.ey = {0.f, 0.f, 1.f};
  p.n = {0.f, -1.f, 0.f};  // up, towards the camera above the table
  p.s = 2.f * r;
  p.count = 18;
  return p;
}

// The grazing puddle with the default surface (anisotropic kernels, gap fill, narrow-range
// filter): its normals must be the plane's within the slope of the ellipsoids' upper envelope,
// as face-on (AnisotropicSheetHasThePlanesNormal). Interior particles at spacing s = 2 r are
// discs (A, A, A / 4), A = 4^(1/3) 1.5 r; every point of the layer is within s / sqrt(2) of a
// centre, where the nearest disc's cap (the highest of identical discs) has slope
// (1/4) (rho / A) / sqrt(1 - (rho / A)^2) = 0.18: 10.5 degrees. The filter measures every sample
// against the centre's tangent plane, so a plane passes unchanged whatever its angle, and over the
// layer's interior (one spacing plus the filter's half-width from its rim) it averages the
// envelope's differences from that plane, which cannot tilt it further. The 8-bit normal image
// adds 0.5 degree. With the centre depth as the range reference, most of the window's samples
// are a different depth (4.6 mm per row against mu = 3 cm): the vertical pass drops those behind
// and clamps those in front, and the normals swing by tens of degrees from row to row (bands).
TEST(RenderFluidSurface, GrazingPuddleHasThePlanesNormal) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = grazing_K();
  const Plane pl = grazing_puddle();
  const float r = 0.01f;
  const Pixels im = anisotropic_normals(pl.particles(), r, K, kGW, kGH);
  const float inner = 0.5f * (pl.count - 1) * pl.s - pl.s - 6.f * r;
  const float bound = disc_envelope_bound(r, pl.s);
  float worst = 0.f, sum = 0.f, row_jump = 0.f;
  int n = 0;
  for (int u = 0; u < kGW; ++u) {
    float above = -1.f;  // the previous row's deviation in this column (-1: none)
    for (int v = 0; v < kGH; ++v) {
      float a, b, z;
      pl.hit(K, u, v, a, b, z);
      if (z <= 0.f || std::abs(a) > inner || std::abs(b) > inner) {
        above = -1.f;
        continue;
      }
      const float deg = normal_off_plane(im, u, v, pl.n);
      if (above >= 0.f) row_jump = std::max(row_jump, std::abs(deg - above));
      above = deg;
      worst = std::max(worst, deg), sum += deg, ++n;
    }
  }
  std::printf(
      "%d pixels: normal off the plane's by %.2f degrees on average, %.2f at most (bound %.1f); largest "
      "change from one row to the next %.2f\n",
      n, sum / std::max(n, 1), worst, bound, row_jump);
  EXPECT_GT(n, 1000);
  EXPECT_LE(worst, bound);
}

// The grazing puddle with a blob of water in front of it: 3 x 3 x 3 particles at spacing 2 r,
// centred 0.42 m ahead and 6 cm above the puddle's particles (more than the anisotropy's
// neighbourhood of 6 r from any of them, so the puddle's kernels are the same as alone). The
// blob hides the puddle from 0.59 m on, 17 cm behind it: a depth discontinuity far beyond mu.
// The blob must keep its own depth: a pixel whose ray passes within r of its middle particle meets
// that particle's sphere before its centre depth, and no pass may move it back by more than mu
// (samples more than mu behind the reference are left out). Every other pixel over the puddle's
// interior must hold either the puddle's depth or, where the blob can be (the ray within its
// centres' box grown by the longest axis a kernel can have, 4^(2/3) 1.5 r, a needle at the
// axis-ratio clamp), the blob's (its farthest centre plus that axis, plus mu). The puddle's: between
// the plane (plus 1 mm for the filter's averaging of the envelope's perspective) and the
// envelope's top, 0.94 r above the plane at most (the thickest planar disc), seen along the ray;
// and nearer by what the narrow range lets the blob's samples pull: each pass clamps them at mu in
// front of its reference, so it moves a depth forward by at most mu, and 2 filter_iterations
// passes (x, y) run.
TEST(RenderFluidSurface, GrazingPuddleAndABlobInFrontStayApart) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = grazing_K();
  const Plane pl = grazing_puddle();
  const float r = 0.01f, mu = 3.f * RenderParams{}.filter_depth_sigma * r;
  std::vector<vec3> x = pl.particles();
  const vec3 blob{0.f, pl.c.y - 0.06f - 2.f * r, 0.42f};
  for (int k = -1; k <= 1; ++k)
    for (int j = -1; j <= 1; ++j)
      for (int i = -1; i <= 1; ++i) x.push_back(blob + vec3{2.f * r * i, 2.f * r * j, 2.f * r * k});
  std::vector<std::uint32_t> ph;
  RenderParams p = surface_params();
  p.fluid_anisotropy = true;
  Renderer rd(p, kGW, kGH);
  rd.draw(fluid_list(x, ph, r), camera(K));
  const Renderer::FluidImages f = rd.read_fluid_images();
  const float needle = std::cbrt(16.f) * 1.5f * r, pull = 2.f * RenderParams{}.filter_iterations * mu;
  const float reach = 2.f * std::sqrt(3.f) * r + needle, blob_back = blob.z + 2.f * r + needle + mu;
  const float inner = 0.5f * (pl.count - 1) * pl.s - pl.s - 6.f * r;
  int blob_px = 0, puddle_px = 0, beside = 0, mixed = 0;
  float worst_pull = 0.f, worst_push = -1.f;
  for (int v = 0; v < kGH; ++v)
    for (int u = 0; u < kGW; ++u) {
      const vec3 ray{(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.f};
      const vec3 dir = ray * (1.f / std::sqrt(dot(ray, ray)));
      const vec3 off = blob - dir * dot(blob, dir);
      const float miss = std::sqrt(dot(off, off));  // the ray's distance from the blob's middle
      const float d = depth_at(f, u, v);
      if (miss <= r) {
        ++blob_px;
        EXPECT_GT(d, 0.f) << "no depth on the blob at " << u << "," << v;
        EXPECT_LE(d, blob.z + mu) << "the blob pulled back at " << u << "," << v;
        worst_push = std::max(worst_push, d - blob.z);
        continue;
      }
      float a, b, z;
      pl.hit(K, u, v, a, b, z);
      if (z <= 0.f || std::abs(a) > inner || std::abs(b) > inner) continue;
      const float top = 0.94f * r / -dot(pl.n, ray);  // the envelope's top, in depth along this ray
      if (d >= z - top - pull && d <= z + 1e-3f) {
        worst_pull = std::max(worst_pull, z - top - d);
        ++puddle_px;
        beside += miss <= reach ? 1 : 0;
      } else if (!(miss <= reach && d > 0.f && d <= blob_back)) {
        ++mixed;
        ADD_FAILURE() << "depth " << d << " at " << u << "," << v << ": neither the puddle's (" << z - top - pull
                      << ".." << z + 1e-3f << ") nor the blob's";
        if (mixed > 20) return;
      }
    }
  std::printf(
      "blob %d pixels, at most %.1f mm behind its middle's centre (allowed %.0f); puddle %d pixels, %d of "
      "them where the blob could be, pulled forward %.1f mm at most (allowed %.0f); %d neither\n",
      blob_px, worst_push * 1e3f, mu * 1e3f, puddle_px, beside, worst_pull * 1e3f, pull * 1e3f, mixed);
  EXPECT_GT(blob_px, 50);
  EXPECT_GT(puddle_px, 2000);
  EXPECT_GT(beside, 500) << "the test needs the puddle beside the blob's image";
}

// A DrawList that brings its own ellipsoids must bring FluidEllipsoids::kVec4s of them per
// particle: a wrong count is the caller's error, named, not a read past the end of its span.
TEST(RenderFluidSurface, EllipsoidsOfTheWrongCountAreAnError) {
  SEAMLESS_REQUIRE_EGL();
  const std::vector<vec3> x = {{0.f, 0.f, 0.3f}, {0.02f, 0.f, 0.3f}};
  std::vector<std::uint32_t> ph;
  RenderParams p = surface_params();
  p.fluid_anisotropy = true;
  Renderer rd(p, kW, kH);
  if (!rd.uses_compute_splat()) GTEST_SKIP() << "no compute splats: the renderer draws spheres";
  DrawList list = fluid_list(x, ph, 0.01f);
  const std::vector<vec4> one(FluidEllipsoids::kVec4s, vec4{0.f, 0.f, 0.3f, 0.01f});  // one particle's
  list.ellipsoids = one;
  try {
    rd.draw(list, camera(small_K()));
    FAIL() << "no error for " << one.size() << " ellipsoid vec4s for 2 particles";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("ellipsoid"), std::string::npos) << e.what();
  }
}

// A lone particle (no neighbour: the anisotropy leaves it a sphere) 0.3 m ahead is drawn as a
// drop of the particle's own radius r, not the splat radius 1.5 r that closes a continuous
// surface: every pixel with fluid depth has a ray within r of the centre (the depth is the exact
// ray-sphere entry), and the disc is filled (the pixels whose ray passes within 0.9 r). Its
// normals are the sphere's: the filter leaves the drop as splatted, and the normal pass's
// one-sided differences over one pixel are secants, whose direction is the sphere's at some point
// between the pixel and its neighbour: off by at most the normal's change over one pixel outwards,
// asin(q + 1 / R) - asin(q) at q = rho / r on a sphere of R pixels radius; checked within
// rho <= 0.8 r, plus 0.5 degree (8 bits).
// Drawn at 1.5 r and flattened by the filter, it was a disc larger than the drop, facing the camera.
TEST(RenderFluidSurface, LoneParticleIsADropOfItsOwnSize) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const float r = 0.01f;
  const vec3 c{0.02f, -0.01f, 0.3f};
  std::vector<vec3> x = {c};
  std::vector<std::uint32_t> ph;
  RenderParams p = surface_params();
  p.fluid_anisotropy = true;
  p.stage_images = true;
  Renderer rd(p, kW, kH);
  rd.draw(fluid_list(x, ph, r), camera(K));
  ASSERT_TRUE(rd.uses_compute_splat());
  const Renderer::FluidImages f = rd.read_fluid_images();
  const StageImage* st = nullptr;
  for (const StageImage& s : rd.stage_images())
    if (s.name == "3_normals") st = &s;
  ASSERT_NE(st, nullptr);
  const Pixels im(st->image);
  const float R = kF * r / c.z;  // the drop's radius in pixels (about)
  int drawn = 0, outside = 0, missing = 0, checked = 0;
  float worst_excess = 0.f, worst_normal = -1e9f;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      const vec3 ray{(u - K.cx) / K.fx, (v - K.cy) / K.fy, 1.f};
      const vec3 dir = ray * (1.f / std::sqrt(dot(ray, ray)));
      const float along = dot(c, dir);
      const vec3 off = c - dir * along;
      const float rho = std::sqrt(dot(off, off));
      const float d = depth_at(f, u, v);
      if (d > 0.f) {
        ++drawn;
        if (rho > r * (1.f + 1e-4f)) ++outside, worst_excess = std::max(worst_excess, rho / r - 1.f);
      } else if (rho < 0.9f * r) {
        ++missing;
      }
      if (d <= 0.f || rho > 0.8f * r) continue;
      // The sphere's normal where this ray enters it.
      const float t = along - std::sqrt(r * r - rho * rho);
      vec3 n = dir * t - c;
      n = n * (1.f / std::sqrt(dot(n, n)));
      const float q = rho / r;
      const float bound = (std::asin(std::min(1.f, q + 1.f / R)) - std::asin(q)) * 180.f / 3.14159265f + 0.5f;
      const float deg = normal_off_plane(im, u, v, n);
      worst_normal = std::max(worst_normal, deg - bound);
      EXPECT_LE(deg, bound) << "not the sphere's normal at " << u << "," << v;
      ++checked;
    }
  std::printf(
      "drop of %.1f pixels radius: %d pixels drawn, %d outside its radius (by %.0f %% at most), %d missing "
      "inside; normals at worst %.2f degrees inside their bound over %d pixels\n",
      R, drawn, outside, worst_excess * 100.f, missing, -worst_normal, checked);
  EXPECT_GT(drawn, 50);
  EXPECT_EQ(outside, 0);
  EXPECT_EQ(missing, 0);
  EXPECT_GT(checked, 50);
}

// A lone particle lying on a surface is a sessile drop, not a bead (splat.glsl, "Lone drops at
// rest"). The camera looks straight down at a floor 0.5 m away (the Kinect view of a flat depth
// image; world = eye, so up is -z, towards the camera). A particle of r = 1 cm whose bottom touches
// the floor is drawn as a pancake of height H = 3.1 mm and radius a = sqrt(16 r^3 / (11 H)) =
// 2.17 cm on the floor, so the fluid covers the disc of radius a around the touch point's pixel
// (all of it within 0.8 a, none beyond a plus a pixel), no depth is nearer than its top, 0.5 - H
// (less 1 mm), and at the touch point the depth is the top's (a plane: float rounding only, within
// 0.1 mm), tagged as a drop lying flat. Two such drops 1.2 a apart overlap, and water that touches
// is one body. The particles rest 4 mm into and 3 mm above the floor (the solver's particles rest
// on the scan's bumpy particles; within the rest test's tolerance), and each drop is laid on the
// measured floor: along the row through their touch points every pixel between them meets the one
// flat top (each such pixel is within 0.6 a of a touch point, inside either top's sqrt(3)/2 a), so
// the depth there is 0.5 - H within 0.1 mm. (Two domes would meet in a crease there, 0.2 H = 0.6 mm
// lower at the midpoint; tops at the particles' heights would be 7 mm apart.) The same particle 5 cm above the floor is
// a drop in the air: a bead of its own radius, its depth the sphere's front at the centre (within 1 mm), tagged as a
// drop, not flat.
TEST(RenderFluidSurface, LoneDropAtRestLiesFlat) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = small_K();
  const float r = 0.01f, floor_z = 0.5f;
  const float H = 2.f * 2.7e-3f * std::sin(35.f * 3.14159265f / 180.f), a = std::sqrt(16.f * r * r * r / (11.f * H));
  std::vector<uchar3> rgb(static_cast<std::size_t>(kW) * kH, kTableGrey);
  std::vector<float> depth(rgb.size(), floor_z);
  RenderParams p = surface_params();
  p.view = RenderView::kinect;
  p.fluid_anisotropy = true;
  auto render = [&](const std::vector<vec3>& x) {
    Renderer rd(p, kW, kH);
    rd.set_kinect_view(Image<uchar3>::from_host(rgb, kW, kH, Device::CPU),
                       Image<float>::from_host(depth, kW, kH, Device::CPU), K, SE3::identity());
    std::vector<std::uint32_t> ph;
    DrawList d = fluid_list(x, ph, r);
    d.up = {0.f, 0.f, -1.f};
    rd.draw(d, RenderCamera{});
    EXPECT_TRUE(rd.uses_compute_splat());
    return rd.read_fluid_images();
  };
  auto pixel = [&](float x, float y, float z) { return vec3{K.cx + K.fx * x / z, K.cy + K.fy * y / z, 0.f}; };
  const vec3 c = pixel(0.02f, -0.01f, floor_z);  // the touch point
  const float R = K.fx * a / floor_z;            // the disc's radius in pixels
  const Renderer::FluidImages flat = render({{0.02f, -0.01f, floor_z - r}});
  int inside = 0, missing = 0, outside = 0;
  float nearest = 1e9f;
  for (int v = 0; v < kH; ++v)
    for (int u = 0; u < kW; ++u) {
      const float rho = std::hypot(u - c.x, v - c.y), d = depth_at(flat, u, v);
      if (d > 0.f) nearest = std::min(nearest, d), ++inside;
      if (d > 0.f && rho > R + 1.f) ++outside;
      if (d <= 0.f && rho < 0.8f * R) ++missing;
    }
  const float centre = depth_at(flat, static_cast<int>(std::lround(c.x)), static_cast<int>(std::lround(c.y)));
  std::printf(
      "at rest: disc of %.1f pixels radius, %d pixels drawn, %d missing inside 0.8 a, %d outside a; "
      "nearest depth %.4f m (top %.4f), centre %.4f\n",
      R, inside, missing, outside, nearest, floor_z - H, centre);
  EXPECT_GT(inside, 0.6f * 3.14159f * R * R);
  EXPECT_EQ(missing, 0);
  EXPECT_EQ(outside, 0);
  EXPECT_GE(nearest, floor_z - H - 1e-3f);
  EXPECT_NEAR(centre, floor_z - H, 1e-4f);
  EXPECT_EQ(drop_tag(centre), 3u) << "a drop at rest is a drop lying flat";

  const float half = 0.6f * a, y = -0.01f;
  const Renderer::FluidImages pair = render({{-half, y, floor_z - r + 4e-3f}, {half, y, floor_z - r - 3e-3f}});
  const vec3 left = pixel(-half, y, floor_z), right = pixel(half, y, floor_z);
  const int row = static_cast<int>(std::lround(left.y));
  float worst = 0.f;
  int checked = 0;
  for (int u = static_cast<int>(std::ceil(left.x)); u <= static_cast<int>(std::floor(right.x)); ++u, ++checked) {
    const float d = depth_at(pair, u, row);
    worst = std::max(worst, std::fabs(d - (floor_z - H)));
    EXPECT_EQ(drop_tag(d), 3u) << "pixel " << u << "," << row;
  }
  std::printf("two drops 1.2 a apart: %d pixels between them, depth at worst %.2f mm from the top\n", checked,
              worst * 1e3f);
  EXPECT_GT(checked, static_cast<int>(R));
  EXPECT_LT(worst, 1e-4f) << "drops that touch are one flat body";

  const float lift = 0.05f, z_bead = floor_z - r - lift;
  const Renderer::FluidImages bead = render({{0.02f, -0.01f, z_bead}});
  const vec3 b = pixel(0.02f, -0.01f, z_bead);
  const float front = depth_at(bead, static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(b.y)));
  std::printf("in the air: depth %.4f m at the centre (sphere's front %.4f)\n", front, z_bead - r);
  EXPECT_NEAR(front, z_bead - r, 1e-3f);
  EXPECT_EQ(drop_tag(front), 1u) << "a drop in the air is a bead";
}
// The grazing puddle's front rim, with the particles jittered as a real spread layer lies (each
// moved by up to a quarter spacing along the table, a fixed pseudo-random pattern): the rim runs
// along the image rows, and at the rim the filter's pass along the columns is one-sided, so its
// result differs from column to column (each column holds other ellipsoids' edges). Only a pass
// along the rows after it can smooth that. The last pass is a normalised average along the row
// over a biweight window of half-width R = filter_max_px (24 pixels here: 6 r projected at 0.55 m
// is wider), so a normal from it can turn from one column to the next by about the whole turn of
// the rim's normal (at most 90 degrees, from facing the camera to lying along the image) over the
// window's width 2 R: 1.9 degrees. The 90th percentile over the rim's pixels is held to that (the
// rim's last pixel in each column, where the fluid ends in a one-pixel step, can exceed it). When
// every iteration ended with the column pass, the rim showed vertical streaks: 9.5 degrees.
TEST(RenderFluidSurface, GrazingPuddlesRimHasNoStreaks) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = grazing_K();
  const Plane pl = grazing_puddle();
  const float r = 0.01f;
  std::vector<vec3> x = pl.particles();
  std::uint32_t state = 12345u;
  auto jitter = [&] {  // in [-0.25, 0.25) spacings (a linear congruential generator)
    state = state * 1664525u + 1013904223u;
    return 0.5f * pl.s * ((state >> 8) / static_cast<float>(1u << 24) - 0.5f);
  };
  for (vec3& q : x) q = q + pl.ex * jitter() + pl.ey * jitter();
  const Pixels im = anisotropic_normals(x, r, K, kGW, kGH);
  auto normal = [&](int u, int v) {
    const uchar3 q = im.at(u, v);
    const vec3 n{q.x / 127.5f - 1.f, q.y / 127.5f - 1.f, q.z / 127.5f - 1.f};
    return n * (1.f / std::sqrt(dot(n, n)));
  };
  auto has_fluid = [&](int u, int v) {  // the normals stage is black where there is no fluid
    const uchar3 q = im.at(u, v);
    return q.x != 0 || q.y != 0 || q.z != 0;
  };
  const float half = 0.5f * (pl.count - 1) * pl.s;
  std::vector<float> turn;  // degrees between the normals of neighbouring columns
  for (int v = 0; v < kGH; ++v)
    for (int u = 0; u + 1 < kGW; ++u) {
      float a, b, z;
      pl.hit(K, u, v, a, b, z);
      // The front rim's band (the first row of particles and a spacing beyond), away from the
      // side rims by the filter's reach.
      if (z <= 0.f || std::abs(a) > half - 3.f * pl.s || b > -half + pl.s || b < -half - pl.s) continue;
      if (!has_fluid(u, v) || !has_fluid(u + 1, v)) continue;
      turn.push_back(std::acos(std::clamp(dot(normal(u, v), normal(u + 1, v)), -1.f, 1.f)) * 180.f / 3.14159265f);
    }
  ASSERT_GT(turn.size(), 1000u);
  std::sort(turn.begin(), turn.end());
  const float p90 = turn[turn.size() * 9 / 10];
  const float bound = 90.f / (2.f * RenderParams{}.filter_max_px);
  std::printf(
      "%zu rim pixels: the normal turns from one column to the next by %.2f degrees (90th percentile; bound %.2f)\n",
      turn.size(), p90, bound);
  EXPECT_LE(p90, bound);
}
}  // namespace
}  // namespace seamless::test
