// Issue #18 ("Looks real") on a real Kinect frame: frame 130 of tum_fr1_rpy_000-149 (a desk with
// papers and a keyboard at about 1 m), read with the TUM reader (undistorted, freiburg1
// intrinsics), pose identity (world = camera frame). The desk's plane is fitted to the frame's
// depth; a cube and a slab of fluid rest on it.
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

#include "core/error.hpp"
#include "io/input_params.hpp"
#include "io/png_io.hpp"
#include "io/tum_source.hpp"
#include "kernels/physics/particle_math.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

const char* const kFolder = "tum_fr1_rpy_000-149";
constexpr int kFrame = 130;

#define REQUIRE_REAL_FRAME()                                                                     \
  SEAMLESS_REQUIRE_EGL();                                                                        \
  if (!std::filesystem::is_directory(std::string(SEAMLESS_TEST_DATA) + "/" + kFolder))           \
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
    in.source = "tum";
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
  vec3 point(int u, int v) const { return f.intrinsics.unproject(static_cast<float>(u), static_cast<float>(v), depth(u, v)); }
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
  p.view = "kinect";
  p.light_dir = desk_light(s);
  return p;
}

// A cube of half size `half` resting on the desk below pixel (u, v), turned by `yaw` about n.
RigidDraw cube_on_desk(const RealFrame& s, float u, float v, float half, float yaw) {
  RigidDraw r;
  const vec3 a = s.t1 * std::cos(yaw) + s.t2 * std::sin(yaw), b = cross(s.n, a);  // b = n x a
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

// sRGB level -> linear (IEC 61966-2-1), as the renderer's color.glsl.
float linear(std::uint8_t c) {
  const float x = c / 255.f;
  return x <= 0.04045f ? x / 12.92f : std::pow((x + 0.055f) / 1.055f, 2.4f);
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
//  - Lit: no blocker within reach, the shader returns the colour untouched; one level of
//    tolerance.
//  - The contact: umbra pixels within 1 cm of the cube's base must exist (the shadow reaches the
//    edge where the cube stands, the contact shadow) and are in the umbra test above.
//  - No acne: the cube's faces that face the light (nothing can shadow them: the cube is
//    convex) look the same with shadows on and off, within one level; self-shadowing artefacts
//    would darken them in speckles.
TEST(RenderLooks, CubeShadowOnTheRealDesk) {
  REQUIRE_REAL_FRAME();
  const RealFrame& s = real_frame();
  std::printf("desk plane: n (%.3f %.3f %.3f), %.3f m from the camera, rms %.2f mm, %.0f %% inliers\n", s.n.x, s.n.y,
              s.n.z, -s.d, 1e3f * s.rms, 100.f * s.inliers);
  ASSERT_LT(s.rms, 0.004f) << "the desk plane fit is off (Kinect noise at 1 m: about 2 mm)";
  const float half = 0.04f;
  const ShadowFrames fr = render_cube(s, kinect_params(s), cube_on_desk(s, 520.f, 405.f, half, 0.5f));
  const vec3 L = normalize(fr.p.light_dir);
  float z0 = 1e30f;
  for (int k = 0; k < 8; ++k) {
    const vec3 c{(k & 1) ? half : -half, (k & 2) ? half : -half, (k & 4) ? half : -half};
    z0 = std::min(z0, dot(L, fr.cube.world_T_body * c));
  }
  const float tan_a = std::tan(0.5f * fr.p.light_angle * kernels::kPi / 180.f);
  const float texel = 2.f * std::sqrt(3.f) * half / (fr.p.shadow_map_size - 4);
  const float k = fr.p.shadow_strength;
  int umbra = 0, contact = 0, lit = 0, lit_faces = 0;
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
        EXPECT_LE(max_diff(on, off), 1) << "shadow outside the cube's shadow at " << u << "," << v;
      }
    }
  std::printf("umbra %d px (contact %d), lit %d px, lit cube faces %d px\n", umbra, contact, lit, lit_faces);
  EXPECT_GT(umbra, 1000);
  EXPECT_GT(contact, 30);
  EXPECT_GT(lit, 200000);
  EXPECT_GT(lit_faces, 500);
}

}  // namespace
}  // namespace seamless::test
