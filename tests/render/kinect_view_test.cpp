// Kinect view: the RGB image is the background, its depth hides virtual objects behind the real
// surface, and the virtual camera is the sensor's exact pinhole model and tracked pose.
#include <cmath>

#include "core/phase.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

struct KinectScene {
  Intrinsics K = intrinsics(120.f, 83.3f, 57.1f, 160, 120);  // off-centre principal point on purpose
  SE3 world_T_camera{rotation({0.2f, 1.f, 0.1f}, 0.4f), {0.5f, -0.2f, 1.0f}};
  Image<uchar3> rgb;
  Image<float> depth;
  // A real wall 1.5 m away over the left half of the image (u < 80); no reading on the right.
  KinectScene() {
    std::vector<uchar3> c(static_cast<std::size_t>(K.width) * K.height);
    std::vector<float> d(c.size());
    for (int v = 0; v < K.height; ++v)
      for (int u = 0; u < K.width; ++u) {
        const std::size_t i = static_cast<std::size_t>(v) * K.width + u;
        c[i] = {static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(2 * v), 40};
        d[i] = u < 80 ? 1.5f : 0.f;
      }
    rgb = Image<uchar3>::from_host(c, K.width, K.height, Device::CPU);
    depth = Image<float>::from_host(d, K.width, K.height, Device::CPU);
  }
  uchar3 rgb_at(int u, int v) const { return rgb.to_host()[static_cast<std::size_t>(v) * K.width + u]; }
};

// Renders one sphere (a debug particle) at camera coordinates `c` and returns the frame.
Pixels render_sphere(const KinectScene& s, vec3 c, float radius, int W, int H) {
  RenderParams p;
  p.view = RenderView::kinect;
  p.fluid = FluidDraw::particles;
  Renderer r(p, W, H);
  r.set_kinect_view(s.rgb, s.depth, s.K, s.world_T_camera);
  const std::vector<vec3> x = {s.world_T_camera * c};
  const std::vector<std::uint32_t> ph = {phase::kFluid};
  DrawList list;
  list.positions = x, list.phases = ph, list.particle_radius = radius;
  return Pixels(r.render(list, RenderCamera{}));
}

// Pixel of camera point c with the sensor's intrinsics (what the test checks the render against).
vec2 project(const KinectScene& s, vec3 c) { return s.K.project(c); }

TEST(RenderKinectView, BackgroundIsTheImage) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  Pixels img = render_sphere(s, {0.f, 0.f, -5.f}, 0.05f, s.K.width, s.K.height);  // behind the camera
  for (int v = 0; v < s.K.height; ++v)
    for (int u = 0; u < s.K.width; ++u) ASSERT_TRUE(same(img.at(u, v), s.rgb_at(u, v))) << u << "," << v;
}

// A sphere of radius r at depth z covers a disc of radius about f r / z around its projected
// centre. The centre pixel must show the sphere (in front) or the image (behind the wall); pixels
// 1.5 projected radii away are background in both cases.
TEST(RenderKinectView, SphereBehindWallIsHiddenInFrontIsVisible) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  const float r = 0.06f;
  for (float z : {1.0f, 2.0f}) {
    const vec3 c{-0.35f * z, 0.1f * z, z};  // projects into the wall's half (u ~ 41)
    const vec2 px = project(s, c);
    ASSERT_LT(px.x + 1.5f * 120.f * r / z, 79.f);
    Pixels img = render_sphere(s, c, r, s.K.width, s.K.height);
    const int u = static_cast<int>(std::lround(px.x)), v = static_cast<int>(std::lround(px.y));
    if (z < 1.5f) {
      EXPECT_GT(max_diff(img.at(u, v), s.rgb_at(u, v)), 60) << "sphere in front of the wall must be visible";
      EXPECT_GT(img.at(u, v).z, img.at(u, v).x) << "fluid particles are drawn blue";
    } else {
      EXPECT_TRUE(same(img.at(u, v), s.rgb_at(u, v))) << "sphere behind the wall must be hidden";
    }
    const int off = static_cast<int>(std::ceil(1.5f * 120.f * r / z)) + 1;
    for (auto [du, dv] : {std::pair{off, 0}, {-off, 0}, {0, off}, {0, -off}})
      EXPECT_TRUE(same(img.at(u + du, v + dv), s.rgb_at(u + du, v + dv))) << du << "," << dv;
  }
}

// Where the sensor has no reading nothing real is there: a sphere at 2 m is visible.
TEST(RenderKinectView, NoDepthReadingDoesNotOcclude) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  const vec3 c{0.3f * 2.f, -0.1f * 2.f, 2.f};  // u ~ 119, right half
  const vec2 px = project(s, c);
  Pixels img = render_sphere(s, c, 0.06f, s.K.width, s.K.height);
  const int u = static_cast<int>(std::lround(px.x)), v = static_cast<int>(std::lround(px.y));
  EXPECT_GT(max_diff(img.at(u, v), s.rgb_at(u, v)), 60);
}

// A framebuffer larger than the sensor image (2x): the intrinsics are scaled, so the sphere lands
// at twice the pixel coordinates (pixel centres: u' = 2 (u + 0.5) - 0.5).
TEST(RenderKinectView, ScaledFramebufferKeepsAlignment) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  const vec3 c{-0.35f, 0.1f, 1.f};
  const vec2 px = project(s, c);
  Pixels img = render_sphere(s, c, 0.03f, 2 * s.K.width, 2 * s.K.height);
  const int u = static_cast<int>(std::lround(2.f * (px.x + 0.5f) - 0.5f));
  const int v = static_cast<int>(std::lround(2.f * (px.y + 0.5f) - 0.5f));
  EXPECT_GT(img.at(u, v).z, img.at(u, v).x + 40);
  const int off = static_cast<int>(std::ceil(1.5f * 240.f * 0.03f)) + 1;
  EXPECT_LT(img.at(u + off, v).z, 60) << "outside the sphere: the image (blue channel 40)";
}

}  // namespace
}  // namespace seamless::test
