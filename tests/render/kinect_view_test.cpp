// Kinect view: the RGB image is the background, its depth hides virtual objects behind the real
// surface, and the virtual camera is the sensor's exact pinhole model and tracked pose.
#include <cmath>
#include <vector>

#include "core/error.hpp"
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

// Renders one sphere (a debug particle) at camera coordinates `c` and returns the frame, showing
// the part `region` of the image (empty: all of it).
// `planes`: surfaces the camera did not measure (world n . x = w).
Pixels render_sphere(const KinectScene& s, vec3 c, float radius, int W, int H, PixelRect region = {},
                     const std::vector<vec4>& planes = {}) {
  RenderParams p;
  p.view = RenderView::kinect;
  p.fluid = FluidDraw::particles;
  Renderer r(p, W, H);
  r.set_kinect_view(s.rgb, s.depth, s.K, s.world_T_camera, region);
  r.set_unmeasured_planes(planes);
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

// A surface the camera did not measure (a table top that returned no depth): the right half of
// the image has no reading, and a plane 0.3 m below the optical axis (camera y runs down) is given
// in world coordinates. A sphere of 0.1 m resting on it at 2 m, in that half, shows its upper part
// and hides its lower part: at pixel row 70 the ray (y = 0.107 z) meets the plane at 2.8 m, behind
// the sphere's front at ~1.95 m; at row 80 (y = 0.191 z) it meets the plane at 1.57 m, in front
// of the sphere. Without the plane both rows show the sphere; with it, the left half (with
// readings) is as before.
TEST(RenderKinectView, UnmeasuredPlaneHidesWhatIsBelowIt) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  const vec3 n = s.world_T_camera.rotate(vec3{0.f, 1.f, 0.f});
  const std::vector<vec4> plane = {{n.x, n.y, n.z, 0.3f + dot(n, s.world_T_camera.t)}};
  const vec3 c{0.6f, 0.3f, 2.f};
  const int u = static_cast<int>(std::lround(project(s, c).x));
  ASSERT_GT(u - 120.f * 0.1f / 2.f, 81.f) << "the sphere must lie in the half without readings";
  const Pixels with = render_sphere(s, c, 0.1f, s.K.width, s.K.height, {}, plane);
  const Pixels without = render_sphere(s, c, 0.1f, s.K.width, s.K.height);
  for (const Pixels* img : {&with, &without})
    EXPECT_GT(max_diff(img->at(u, 70), s.rgb_at(u, 70)), 60) << "the sphere's upper part, above the plane";
  EXPECT_GT(max_diff(without.at(u, 80), s.rgb_at(u, 80)), 60) << "no plane: nothing hides the lower part";
  EXPECT_TRUE(same(with.at(u, 80), s.rgb_at(u, 80))) << "the plane hides the sphere's lower part";
  // The same sphere behind the wall in the left half (readings at 1.5 m) stays hidden either way.
  const vec3 behind{-0.35f * 2.f, 0.1f * 2.f, 2.f};
  const vec2 pb = project(s, behind);
  const Pixels wall = render_sphere(s, behind, 0.06f, s.K.width, s.K.height, {}, plane);
  const int ub = static_cast<int>(std::lround(pb.x)), vb = static_cast<int>(std::lround(pb.y));
  EXPECT_TRUE(same(wall.at(ub, vb), s.rgb_at(ub, vb)));
}

// Planes are n . x = w with a unit normal, at most Renderer::kMaxUnmeasuredPlanes of them.
TEST(RenderKinectView, UnmeasuredPlanesAreChecked) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p;
  p.view = RenderView::kinect;
  Renderer r(p, 32, 24);
  EXPECT_THROW(r.set_unmeasured_planes({{0.f, 2.f, 0.f, 1.f}}), Error);
  EXPECT_THROW(r.set_unmeasured_planes(std::vector<vec4>(Renderer::kMaxUnmeasuredPlanes + 1, vec4{0.f, 1.f, 0.f, 0.f})),
               Error);
  EXPECT_NO_THROW(r.set_unmeasured_planes({{0.f, 1.f, 0.f, -0.5f}}));
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

// The frame shows a colour region (as undistortion leaves one) scaled up to the framebuffer: an
// 80 x 60 part at (30, 20) of the 160 x 120 image, so each image pixel covers 2 x 2 framebuffer
// pixels, and framebuffer pixel U shows image column x = 30 + (U + 0.5) / 2 - 0.5 (pixel edges
// map to pixel edges). The image's red channel is its column and green twice its row, so the
// bilinear lookup gives exactly those values (one level of rounding). A sphere lands where the
// cropped and scaled intrinsics put it: U = 2 (u - 30 + 0.5) - 0.5.
TEST(RenderKinectView, ColourRegionIsCroppedAndStaysAligned) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  const PixelRect region{30, 20, 80, 60};
  const vec3 c{-0.35f, 0.1f, 1.f};  // in front of the wall (u ~ 41, v ~ 58)
  const vec2 px = project(s, c);
  Pixels img = render_sphere(s, c, 0.03f, s.K.width, s.K.height, region);
  const float r = 120.f * 0.03f;  // the sphere's projected radius, image pixels
  for (int V = 0; V < s.K.height; ++V)
    for (int U = 0; U < s.K.width; ++U) {
      const float x = 30.f + (U + 0.5f) / 2.f - 0.5f, y = 20.f + (V + 0.5f) / 2.f - 0.5f;
      if (std::hypot(x - px.x, y - px.y) < 1.5f * r + 1.f) continue;  // the sphere
      if (x < 30.f || y < 20.f || x > 109.f || y > 79.f) continue;    // the texture clamps at the image edge only
      ASSERT_NEAR(img.at(U, V).x, x, 1.01f) << U << "," << V;
      ASSERT_NEAR(img.at(U, V).y, 2.f * y, 1.01f) << U << "," << V;
    }
  const int u = static_cast<int>(std::lround(2.f * (px.x - 30.f + 0.5f) - 0.5f));
  const int v = static_cast<int>(std::lround(2.f * (px.y - 20.f + 0.5f) - 0.5f));
  EXPECT_GT(img.at(u, v).z, img.at(u, v).x + 40) << "the sphere at its cropped, scaled pixel";
  const int off = static_cast<int>(std::ceil(2.f * 1.5f * r)) + 1;
  for (auto [du, dv] : {std::pair{off, 0}, {-off, 0}, {0, off}, {0, -off}})
    EXPECT_LT(img.at(u + du, v + dv).z, 60) << "outside the sphere: the image (blue channel 40)";
}

// A framebuffer of another aspect than the region: the region is cut at two sides (centred) to
// the framebuffer's aspect, not stretched. 160 x 60 from the whole 160 x 120 image: rows 30..89.
TEST(RenderKinectView, OtherAspectIsCutNotStretched) {
  SEAMLESS_REQUIRE_EGL();
  KinectScene s;
  Pixels img = render_sphere(s, {0.f, 0.f, -5.f}, 0.05f, 160, 60);  // sphere behind the camera
  for (int V = 0; V < 60; ++V)
    for (int U = 0; U < 160; ++U) ASSERT_TRUE(same(img.at(U, V), s.rgb_at(U, V + 30))) << U << "," << V;
}

}  // namespace
}  // namespace seamless::test
