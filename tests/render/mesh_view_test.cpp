// Mesh view: the scene mesh covers exactly the pixels it projects to, the background the rest.
#include <cmath>

#include "render_test_util.hpp"

namespace seamless::test {
namespace {

// Rectangle at z = 2 seen from the origin: its image is [fx x/z + cx] x [fy y/z + cy]. Pixel
// centres are integers; the edges fall on half-integers, so a margin of one pixel on either side
// of each edge absorbs rounding of the edge equations without admitting a wrong projection.
TEST(RenderMeshView, RectangleCoversItsProjection) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p;
  p.background = {26 / 255.f, 51 / 255.f, 77 / 255.f};  // exact in 8 bits
  const Intrinsics K = intrinsics(100.f, 79.5f, 59.5f, 160, 120);
  Renderer r(p, K.width, K.height);
  const uchar3 red{200, 30, 30};
  r.set_scene_mesh(rectangle(-0.5f, 0.5f, -0.3f, 0.3f, 2.f, red));
  Pixels img(r.render(DrawList{}, camera(K)));
  const uchar3 bg = to_rgb8(p.background);
  const float u0 = 100.f * -0.25f + 79.5f, u1 = 100.f * 0.25f + 79.5f;  // 54.5, 104.5
  const float v0 = 100.f * -0.15f + 59.5f, v1 = 100.f * 0.15f + 59.5f;  // 44.5, 74.5
  int inside = 0, outside = 0;
  for (int v = 0; v < img.h; ++v)
    for (int u = 0; u < img.w; ++u) {
      const bool in = u > u0 + 1 && u < u1 - 1 && v > v0 + 1 && v < v1 - 1;
      const bool out = u < u0 - 1 || u > u1 + 1 || v < v0 - 1 || v > v1 + 1;
      if (in) {
        EXPECT_TRUE(same(img.at(u, v), red)) << u << "," << v;
        ++inside;
      }
      if (out) {
        EXPECT_TRUE(same(img.at(u, v), bg)) << u << "," << v;
        ++outside;
      }
    }
  EXPECT_GT(inside, 40 * 20);
  EXPECT_GT(outside, 160 * 120 / 2);
}

// Any camera: a free camera looking at the rectangle from the side. The rectangle's corners are
// projected here with the pinhole model; pixels inside the projected quadrilateral (shrunk by a
// pixel) are mesh, pixels outside its bounding box (grown by a pixel) are background.
TEST(RenderMeshView, FreeCamera) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p;
  p.background = {0.f, 0.f, 0.f};
  const int W = 200, H = 150;
  Renderer r(p, W, H);
  const uchar3 green{20, 220, 60};
  r.set_scene_mesh(rectangle(-0.5f, 0.5f, -0.5f, 0.5f, 0.f, green));
  const RenderCamera cam = RenderCamera::look_at({1.2f, -0.8f, -2.5f}, {0.1f, 0.f, 0.f}, {0.f, -1.f, 0.f}, 50.f, W, H);
  Pixels img(r.render(DrawList{}, cam));
  const SE3 cT = cam.world_T_camera.inverse();
  std::vector<vec2> q;
  for (vec3 c : {vec3{-0.5f, -0.5f, 0.f}, vec3{0.5f, -0.5f, 0.f}, vec3{0.5f, 0.5f, 0.f}, vec3{-0.5f, 0.5f, 0.f}})
    q.push_back(cam.K.project(cT * c));
  // Signed distance of a pixel to the quadrilateral's edges (convex, either orientation).
  float area = 0.f;
  for (int i = 0; i < 4; ++i) area += q[i].x * q[(i + 1) % 4].y - q[(i + 1) % 4].x * q[i].y;
  const float s = area > 0.f ? 1.f : -1.f;
  auto inside_by = [&](float u, float v) {
    float worst = 1e9f;
    for (int i = 0; i < 4; ++i) {
      const vec2 a = q[i], b = q[(i + 1) % 4];
      const float len = std::hypot(b.x - a.x, b.y - a.y);
      worst = std::min(worst, s * ((b.x - a.x) * (v - a.y) - (b.y - a.y) * (u - a.x)) / len);
    }
    return worst;
  };
  float lo_u = 1e9f, hi_u = -1e9f, lo_v = 1e9f, hi_v = -1e9f;
  for (vec2 c : q)
    lo_u = std::min(lo_u, c.x), hi_u = std::max(hi_u, c.x), lo_v = std::min(lo_v, c.y), hi_v = std::max(hi_v, c.y);
  int inside = 0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u) {
      if (inside_by(static_cast<float>(u), static_cast<float>(v)) > 1.f) {
        EXPECT_TRUE(same(img.at(u, v), green)) << u << "," << v;
        ++inside;
      }
      if (u < lo_u - 1 || u > hi_u + 1 || v < lo_v - 1 || v > hi_v + 1) {
        EXPECT_TRUE(same(img.at(u, v), uchar3{0, 0, 0})) << u << "," << v;
      }
    }
  EXPECT_GT(inside, 500);
}

}  // namespace
}  // namespace seamless::test
