// The realistic look on a real Kinect frame: frame 130 of tum_fr1_rpy_000-149 (a desk with
// papers and a keyboard at about 1 m), read with the TUM reader (undistorted, freiburg1
// intrinsics), pose identity (world = camera frame). The desk's plane is fitted to the frame's
// depth; a cube and a puddle of fluid rest on it.
//   - Shadows: inside the cube's analytic shadow (the receiver's ray towards the light hits the
//     cube) the real image is darker by the configured strength; outside it, unchanged.
//   - Water: the fluid surface covers the projected particle discs (no specks), and where it is
//     thick its colour differs clearly from the camera image.
// With SEAMLESS_RENDER_REVIEW=<dir> the frames are also written there as PNGs, to be looked at.
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <numbers>

#include "core/error.hpp"
#include "core/phase.hpp"
#include "io/input_params.hpp"
#include "io/png_io.hpp"
#include "io/tum_source.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

const char* const kFolder = "tum_fr1_rpy_000-149";
constexpr int kFrame = 130;

#define REQUIRE_REAL_FRAME()                                                           \
  SEAMLESS_REQUIRE_EGL();                                                              \
  if (!std::filesystem::is_directory(std::string(SEAMLESS_TEST_DATA) + "/" + kFolder)) \
  GTEST_SKIP() << "test data folder " << SEAMLESS_TEST_DATA << "/" << kFolder << " is absent"

// The frame and the desk plane (unit normal n towards the camera, tangents t1 (image right) and
// t2 = n x t1), fitted once.
struct RealFrame {
  RgbdFrame f;
  vec3 n, t1, t2;
  float d = 0.f;  // plane: dot(n, x) = d
  float rms = 0.f;
  float inliers = 0.f;  // fraction of the sampled desk points within 1 cm of the plane

  RealFrame() {
    InputParams in;
    in.source = InputSource::tum;
    in.path = std::string(SEAMLESS_TEST_DATA) + "/" + kFolder;
    in.first_frame = kFrame;
    in.max_frames = 1;
    TumSource src(in);
    if (!src.next(f)) throw Error("real_frame_test: no frame " + std::to_string(kFrame) + " in " + in.path);
    fit_desk();
  }
  int w() const { return f.intrinsics.width; }
  int h() const { return f.intrinsics.height; }
  float depth(int u, int v) const { return depth_host[static_cast<std::size_t>(v) * w() + u]; }
  vec3 point(int u, int v) const {
    return f.intrinsics.unproject(static_cast<float>(u), static_cast<float>(v), depth(u, v));
  }
  // Where pixel (u, v)'s ray meets the desk plane.
  vec3 on_plane(float u, float v) const {
    const vec3 ray = f.intrinsics.unproject(u, v, 1.f);
    return ray * (d / dot(n, ray));
  }
  std::vector<float> depth_host;

 private:
  // Least squares over the desk in the lower part of the image (papers and bare desk, above the
  // desk's front edge; the keyboard's corner and the cable stand out by centimetres): the normal is
  // the smallest eigenvector of the points' covariance; then the points within 2 cm, and within
  // 1 cm, of the last plane are fitted again.
  void fit_desk() {
    depth_host = f.depth.to_host();
    std::vector<vec3> all;
    for (int v = 360; v < 450; v += 2)
      for (int u = 150; u < 620; u += 2)
        if (depth(u, v) > 0.f) all.push_back(point(u, v));
    std::vector<vec3> pts = all;
    for (float trim : {0.02f, 0.01f, 0.01f}) {
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const vec3& p : pts) c += Eigen::Vector3d(p.x, p.y, p.z);
      c /= static_cast<double>(pts.size());
      Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
      for (const vec3& p : pts) {
        const Eigen::Vector3d q = Eigen::Vector3d(p.x, p.y, p.z) - c;
        C += q * q.transpose();
      }
      const Eigen::Vector3d e = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(0);
      n = normalize(vec3{static_cast<float>(e.x()), static_cast<float>(e.y()), static_cast<float>(e.z())});
      d = dot(n, vec3{static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())});
      if (d > 0.f) n = -n, d = -d;  // towards the camera (the origin is on the positive side)
      pts.clear();
      double ss = 0.0;
      for (const vec3& p : all) {
        const float r = dot(n, p) - d;
        if (std::abs(r) < trim) pts.push_back(p), ss += double(r) * r;
      }
      rms = static_cast<float>(std::sqrt(ss / std::max<std::size_t>(pts.size(), 1)));
    }
    inliers = static_cast<float>(pts.size()) / static_cast<float>(std::max<std::size_t>(all.size(), 1));
    t1 = normalize(vec3{1, 0, 0} - n * n.x);
    t2 = cross(n, t1);
  }
};

const RealFrame& real_frame() {
  static const RealFrame frame;
  return frame;
}

std::string review_dir() {
  const char* d = std::getenv("SEAMLESS_RENDER_REVIEW");
  if (!d || !*d) return "";
  std::filesystem::create_directories(d);
  return d;
}
void review(const std::string& name, const Image<uchar3>& im) {
  const std::string dir = review_dir();
  if (!dir.empty()) write_png_rgb(dir + "/" + name + ".png", im);
}

// Light from above the desk, tilted towards the camera's left so that the shadow falls beside the
// cube, where the camera sees it.
vec3 desk_light(const RealFrame& s) { return normalize(-s.n - 0.45f * s.t1 + 0.25f * s.t2); }

RenderParams kinect_params(const RealFrame& s) {
  RenderParams p;
  p.view = RenderView::kinect;
  p.light_dir = desk_light(s);
  return p;
}

// A cube of half size `half` resting on the desk below pixel (u, v), turned by `yaw` about n.
RigidDraw cube_on_desk(const RealFrame& s, float u, float v, float half, float yaw) {
  RigidDraw r;
  const vec3 a = s.t1 * std::cos(yaw) + s.t2 * std::sin(yaw), b = cross(s.n, a);   // b = n x a
  r.world_T_body.R = {{{a.x, s.n.x, b.x}, {a.y, s.n.y, b.y}, {a.z, s.n.z, b.z}}};  // columns a, n, b
  r.world_T_body.t = s.on_plane(u, v) + s.n * half;
  r.half_extents = {half, half, half};
  return r;
}

// Where the ray o + t dir (t > 0) meets the box (slab test in its frame), or a negative value.
float ray_box(const RigidDraw& box, vec3 o, vec3 dir, float grow) {
  const SE3 inv = box.world_T_body.inverse();
  const vec3 lo = inv * o, ld = inv.rotate(dir);
  float t0 = 0.f, t1 = 1e30f;
  for (int i = 0; i < 3; ++i) {
    const float e = (&box.half_extents.x)[i] + grow, oo = (&lo.x)[i], dd = (&ld.x)[i];
    if (std::abs(dd) < 1e-12f) {
      if (std::abs(oo) > e) return -1.f;
      continue;
    }
    float a = (-e - oo) / dd, b = (e - oo) / dd;
    if (a > b) std::swap(a, b);
    t0 = std::max(t0, a), t1 = std::min(t1, b);
  }
  return t0 <= t1 ? t0 : -1.f;
}

// CIE 1976 L*a*b* of an sRGB colour (D65 white).
vec3 lab(uchar3 c) {
  const float r = linear(c.x), g = linear(c.y), b = linear(c.z);
  const float X = (0.4124f * r + 0.3576f * g + 0.1805f * b) / 0.95047f;
  const float Y = 0.2126f * r + 0.7152f * g + 0.0722f * b;
  const float Z = (0.0193f * r + 0.1192f * g + 0.9505f * b) / 1.08883f;
  auto f = [](float t) { return t > 216.f / 24389.f ? std::cbrt(t) : (24389.f / 27.f * t + 16.f) / 116.f; };
  return {116.f * f(Y) - 16.f, 500.f * (f(X) - f(Y)), 200.f * (f(Y) - f(Z))};
}
float delta_e(uchar3 a, uchar3 b) { return length(lab(a) - lab(b)); }

// Rendered frames of one scene with shadows off and on, and the camera image as drawn.
struct ShadowFrames {
  RigidDraw cube;
  RenderParams p;
  Pixels bg, off, on;
};

ShadowFrames render_cube(const RealFrame& s, RenderParams p, const RigidDraw& cube) {
  Renderer r(p, s.w(), s.h());
  r.set_kinect_view(s.f.rgb, s.f.depth, s.f.intrinsics, SE3::identity());
  DrawList list;
  list.rigids = {cube};
  r.params().shadows = false;
  Image<uchar3> off = r.render(list, RenderCamera{});
  r.params().shadows = true;
  Image<uchar3> on = r.render(list, RenderCamera{});
  Image<uchar3> bg = r.render(DrawList{}, RenderCamera{});
  review("shadow_cube_off", off);
  review("shadow_cube_on", on);
  return {cube, p, Pixels(bg), Pixels(off), Pixels(on)};
}

float luminance(uchar3 c) { return 0.2126f * linear(c.x) + 0.7152f * linear(c.y) + 0.0722f * linear(c.z); }

// A cube resting on the real desk, lit from above at an angle. For each pixel of the real image
// (a depth reading, not covered by the cube) the measured point P is classified analytically:
// in the umbra when its ray towards the light hits the cube shrunk by a margin, lit when it
// misses the cube grown by the same margin. The margin is what the renderer may blur: the soft
// shadow's filter reaches tan(light_angle / 2) * d (d: P's depth along the light below the
// cube's nearest corner: the penumbra of a blocker at that corner, the widest possible) plus one
// texel of minimum filter, one of the bilinear footprint and one for the rasterised edge; a
// texel is at most the cube's diagonal over the map's inner size (map extent: the casters'
// bounds, shadow.glsl).
//  - Umbra: every filter tap is blocked, so the linear luminance is (1 - strength) times the
//    unshadowed one; the test demands at least 0.9 of that darkening, plus one 8-bit level of
//    rounding.
//  - Lit: no blocker within reach; the light's share is untouched and the room's share, 1 -
//    strength, loses the form factor F from P to the cube (contact occlusion, occlusion.glsl),
//    computed here by the area integral (box_form_factor) for the normal the renderer estimates
//    from the same depth readings (the surface points kNormalStep pixels to each side, turned to
//    the camera; F = 0 where one has no reading). Each channel within one 8-bit level.
//  - The contact: umbra pixels within 1 cm of the cube's base must exist (the shadow reaches the
//    edge where the cube stands, the contact shadow) and are in the umbra test above.
//  - No acne: the cube's faces that face the light (nothing can shadow them: the cube is
//    convex) look the same with shadows on and off, within one level; self-shadowing artefacts
//    would darken them in speckles.
// The form factor from the real surface at pixel (u, v) to the cube (RigidDraw of half extent
// `half`), for the normal kinect_bg.frag estimates there: 0 where it has none.
float form_factor_to_cube(const RealFrame& s, int u, int v, const RigidDraw& cube, float half) {
  constexpr int kNormalStep = 3;  // kinect_bg.frag's
  if (u < kNormalStep || v < kNormalStep || u + kNormalStep >= s.w() || v + kNormalStep >= s.h()) return 0.f;
  if (s.depth(u + kNormalStep, v) <= 0.f || s.depth(u - kNormalStep, v) <= 0.f || s.depth(u, v + kNormalStep) <= 0.f ||
      s.depth(u, v - kNormalStep) <= 0.f)
    return 0.f;
  const vec3 dx = s.point(u + kNormalStep, v) - s.point(u - kNormalStep, v);
  const vec3 dy = s.point(u, v + kNormalStep) - s.point(u, v - kNormalStep);
  vec3 n = normalize(cross(dx, dy));
  if (dot(n, s.point(u, v)) > 0.f) n = n * -1.f;  // towards the camera
  const SE3 body_T_world = cube.world_T_body.inverse();
  return static_cast<float>(
      box_form_factor(body_T_world * s.point(u, v), body_T_world.rotate(n), {0.f, 0.f, 0.f}, {half, half, half}));
}

TEST(RenderLooks, CubeShadowOnTheRealDesk) {
  REQUIRE_REAL_FRAME();
  const RealFrame& s = real_frame();
  std::printf("desk plane: n (%.3f %.3f %.3f), %.3f m from the camera, rms %.2f mm, %.0f %% inliers\n", s.n.x, s.n.y,
              s.n.z, -s.d, 1e3f * s.rms, 100.f * s.inliers);
  ASSERT_LT(s.rms, 0.004f) << "the desk plane fit is off (Kinect noise at 1 m: about 2 mm)";
  const float half = 0.05f;
  const ShadowFrames fr = render_cube(s, kinect_params(s), cube_on_desk(s, 520.f, 405.f, half, 0.5f));
  const vec3 L = normalize(fr.p.light_dir);
  float z0 = 1e30f;
  for (int k = 0; k < 8; ++k) {
    const vec3 c{(k & 1) ? half : -half, (k & 2) ? half : -half, (k & 4) ? half : -half};
    z0 = std::min(z0, dot(L, fr.cube.world_T_body * c));
  }
  const float tan_a = std::tan(0.5f * fr.p.light_angle * std::numbers::pi_v<float> / 180.f);
  const float texel = 2.f * std::sqrt(3.f) * half / (fr.p.shadow_map_size - 4);
  const float k = fr.p.shadow_strength;
  int umbra = 0, contact = 0, lit = 0, lit_faces = 0;
  float max_F = 0.f;
  for (int v = 0; v < s.h(); ++v)
    for (int u = 0; u < s.w(); ++u) {
      const uchar3 off = fr.off.at(u, v), on = fr.on.at(u, v);
      if (!same(off, fr.bg.at(u, v))) {  // the cube: faces turned to the light must not change
        const vec3 ray = s.f.intrinsics.unproject(static_cast<float>(u), static_cast<float>(v), 1.f);
        const float t = ray_box(fr.cube, {0, 0, 0}, ray, 0.f);
        if (t <= 0.f) continue;  // a rim pixel the rasteriser covered and the ray test does not
        const vec3 q = fr.cube.world_T_body.inverse() * (ray * t);
        int axis = 0;
        for (int i = 1; i < 3; ++i) axis = std::abs((&q.x)[i]) > std::abs((&q.x)[axis]) ? i : axis;
        bool inside_face = true;  // away from the face's edges (2 mm), where the normal is ambiguous
        for (int i = 0; i < 3; ++i) inside_face = inside_face && (i == axis || std::abs((&q.x)[i]) < half - 0.002f);
        vec3 nb{0, 0, 0};
        (&nb.x)[axis] = (&q.x)[axis] > 0.f ? 1.f : -1.f;
        if (inside_face && dot(fr.cube.world_T_body.rotate(nb), -L) > 0.2f) {
          ++lit_faces;
          EXPECT_LE(max_diff(on, off), 1) << "acne on the cube's lit face at " << u << "," << v;
        }
        continue;
      }
      if (s.depth(u, v) <= 0.f) continue;  // no reading: no surface to shadow
      const vec3 P = s.point(u, v);
      const float margin = tan_a * std::max(dot(L, P) - z0, 0.f) + 3.f * texel;
      if (ray_box(fr.cube, P, -L, -margin) > 0.f) {
        ++umbra;
        const float want = (1.f - 0.9f * k) * luminance(off);
        const float level = luminance(on) - luminance(uchar3{static_cast<std::uint8_t>(std::max(on.x - 1, 0)),
                                                             static_cast<std::uint8_t>(std::max(on.y - 1, 0)),
                                                             static_cast<std::uint8_t>(std::max(on.z - 1, 0))});
        EXPECT_LE(luminance(on), want + level) << "not in shadow at " << u << "," << v;
        // Within 1 cm of the cube's footprint on the desk: the contact region.
        const vec3 qb = fr.cube.world_T_body.inverse() * P;
        if (std::max(std::abs(qb.x), std::abs(qb.z)) < half + 0.01f && qb.y < -half + 0.01f) ++contact;
      } else if (ray_box(fr.cube, P, -L, margin) < 0.f) {
        ++lit;
        const float F = form_factor_to_cube(s, u, v, fr.cube, half);
        max_F = std::max(max_F, F);
        for (int i = 0; i < 3; ++i) {
          const std::uint8_t got = (&on.x)[i], was = (&off.x)[i];
          const float level = linear(static_cast<std::uint8_t>(std::min(got + 1, 255))) - linear(got);
          EXPECT_NEAR(linear(got), (k + (1.f - k) * (1.f - F)) * linear(was), level)
              << "lit at " << u << "," << v << " channel " << i << ", F " << F;
        }
      }
    }
  std::printf("umbra %d px (contact %d), lit %d px (form factor to the cube up to %.3f), lit cube faces %d px\n", umbra,
              contact, lit, max_F, lit_faces);
  EXPECT_GT(umbra, 500);
  EXPECT_GT(contact, 30);
  EXPECT_GT(lit, 200000);
  EXPECT_GT(lit_faces, 500);
}

// A resting body of water on the desk below pixel (u, v): particles on a lattice of one diameter
// (PBF's rest spacing) inside half an ellipsoid (semi-axes A along t1, B along t2, height H along
// n), the shape surface tension gives a puddle with a rounded rim. 2 cm particles (the
// realistic look's 2-3 cm at 1-2 m): a few hundred of them.
struct Puddle {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  float r = 0.01f;
  float A = 0.17f, B = 0.13f, H = 0.05f;
  vec3 centre, a, b, n;
  Puddle(const RealFrame& s, float u, float v) : centre(s.on_plane(u, v)), a(s.t1), b(s.t2), n(s.n) {
    const float d = 2 * r;
    for (float h = r; h < H; h += d)
      for (float y = -B; y <= B; y += d)
        for (float xx = -A; xx <= A; xx += d) {
          // Centres one radius inside the surface, so that the spheres fill the shape.
          const float ea = A - r, eb = B - r, eh = H - r;
          if ((xx * xx) / (ea * ea) + (y * y) / (eb * eb) + (h * h) / (eh * eh) > 1.f) continue;
          x.push_back(centre + a * xx + b * y + n * h);
        }
    ph.assign(x.size(), phase::kFluid);
  }
  // Length of the ray t dir (from the camera) inside the half-ellipsoid: the unit sphere after
  // scaling each axis, cut by the desk plane (h >= 0).
  float path(vec3 dir) const {
    const vec3 o = -centre;  // camera in the puddle's frame (a, b, n), unscaled
    const vec3 lo{dot(o, a) / A, dot(o, b) / B, dot(o, n) / H}, ld{dot(dir, a) / A, dot(dir, b) / B, dot(dir, n) / H};
    const float qa = dot(ld, ld), qb = dot(lo, ld), qc = dot(lo, lo) - 1.f, disc = qb * qb - qa * qc;
    if (disc <= 0.f) return 0.f;
    float t0 = (-qb - std::sqrt(disc)) / qa, t1 = (-qb + std::sqrt(disc)) / qa;
    // h = lo.z + t ld.z >= 0 (above the desk): the camera is above it, so cut the far end.
    if (ld.z < 0.f) t1 = std::min(t1, -lo.z / ld.z);
    return std::max(0.f, t1 - std::max(t0, 0.f)) * length(dir);
  }
  void add_to(DrawList& l) const { l.positions = x, l.phases = ph, l.particle_radius = r; }
};

// The eye depth where the ray z * d (d.z = 1) enters the sphere, or a negative value.
float ray_sphere(vec3 d, vec3 c, float r) {
  const float a = dot(d, d), b = dot(d, c), disc = b * b - a * (dot(c, c) - r * r);
  return disc < 0.f ? -1.f : (b - std::sqrt(disc)) / a;
}

// A puddle of a few hundred 2 cm particles resting on the real desk (shadows off: the water's
// own look; its shadow is the cube test's subject), against the camera image drawn alone:
//  (a) no specks: of the pixels inside the projected particle discs (the ray meets a particle's
//      sphere of radius r at least 1 cm in front of the measured desk: the lowest particles sit
//      one radius above the fitted plane and the depth is noisy by a few mm), at least 90 % are
//      visibly changed: CIE76 delta E >= 2.3, one just-noticeable difference (Sharma, Digital
//      Color Imaging Handbook, 2003).
//  (b) colour where thick: over the pixels whose ray runs at least 3 cm through the puddle's
//      shape, the mean delta E is at least 10: beyond "perceptible at a glance" (2-10), where
//      colours read as different. What to expect: Beer-Lambert alone over 3 cm with the default
//      absorption turns a white desk (linear 1, 1, 1) into exp(-0.03 a) per channel; the test
//      computes that colour's delta E from white and demands half of it as well (refraction
//      moves the background, reflection adds a little of the room's colour: neither should cancel
//      the tint), so that the threshold follows render.absorption.
TEST(RenderLooks, WaterOnTheRealDesk) {
  REQUIRE_REAL_FRAME();
  const RealFrame& s = real_frame();
  RenderParams p = kinect_params(s);
  p.shadows = false;
  p.stage_images = !review_dir().empty();
  Renderer r(p, s.w(), s.h());
  r.set_kinect_view(s.f.rgb, s.f.depth, s.f.intrinsics, SE3::identity());
  const Puddle puddle(s, 345.f, 350.f);
  DrawList list;
  puddle.add_to(list);
  const Pixels camera(r.render(DrawList{}, RenderCamera{}));
  const Image<uchar3> frame = r.render(list, RenderCamera{});
  review("water", frame);
  for (const StageImage& st : r.stage_images()) review("water_stage_" + st.name, st.image);
  const Pixels water(frame);
  int disc = 0, disc_seen = 0, thick = 0;
  double sum_de = 0.0;
  for (int v = 0; v < s.h(); ++v)
    for (int u = 0; u < s.w(); ++u) {
      const vec3 ray = s.f.intrinsics.unproject(static_cast<float>(u), static_cast<float>(v), 1.f);
      const float z_scene = s.depth(u, v) > 0.f ? s.depth(u, v) : 1e30f;
      const float de = delta_e(water.at(u, v), camera.at(u, v));
      bool in_disc = false;
      for (const vec3& c : puddle.x) {
        const float z = ray_sphere(ray, c, puddle.r);
        in_disc = in_disc || (z > 0.f && z < z_scene - 0.01f);
      }
      if (in_disc) ++disc, disc_seen += de >= 2.3f ? 1 : 0;
      if (puddle.path(ray) >= 0.03f) ++thick, sum_de += de;
    }
  const float mean_de = static_cast<float>(sum_de / std::max(thick, 1));
  auto srgb8 = [](float lin) {
    const float c = lin <= 0.0031308f ? 12.92f * lin : 1.055f * std::pow(lin, 1.f / 2.4f) - 0.055f;
    return static_cast<std::uint8_t>(std::lround(255.f * c));
  };
  const vec3 a = p.absorption;
  const uchar3 tinted{srgb8(std::exp(-0.03f * a.x)), srgb8(std::exp(-0.03f * a.y)), srgb8(std::exp(-0.03f * a.z))};
  const float expected = delta_e(tinted, uchar3{255, 255, 255});
  std::printf(
      "%zu particles; disc pixels %d, visibly changed %.1f %%; thick pixels %d: mean delta E %.1f "
      "(Beer-Lambert over 3 cm on white: %.1f)\n",
      puddle.x.size(), disc, 100.0 * disc_seen / std::max(disc, 1), thick, mean_de, expected);
  EXPECT_GE(puddle.x.size(), 200u);
  EXPECT_GT(disc, 5000);
  EXPECT_GE(disc_seen, 0.9 * disc) << "specks: the fluid leaves the particles' discs unchanged";
  EXPECT_GT(thick, 2000);
  EXPECT_GE(mean_de, 10.f);
  EXPECT_GE(mean_de, 0.5f * expected);
}

}  // namespace
}  // namespace seamless::test
