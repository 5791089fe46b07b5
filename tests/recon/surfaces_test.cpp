// Horizontal surfaces (src/recon/surfaces.hpp) on meshes whose surfaces are known exactly: a floor,
// a desk top and a box on the desk, plus pieces that must not count (a ramp steeper than the tilt
// limit, the desk's underside).
#include <gtest/gtest.h>

#include <cmath>

#include "recon/surfaces.hpp"

namespace seamless {
namespace {

// A rectangle [x0, x1] x [z0, z1] at height y of 2 cm quads, facing up (or down).
void add_rect(Mesh& m, float x0, float x1, float z0, float z1, float y, bool up = true) {
  const float step = 0.02f;
  const int nx = static_cast<int>(std::lround((x1 - x0) / step)), nz = static_cast<int>(std::lround((z1 - z0) / step));
  for (int i = 0; i < nx; ++i)
    for (int k = 0; k < nz; ++k) {
      const int b = static_cast<int>(m.positions.size());
      const float xa = x0 + i * step, za = z0 + k * step;
      m.positions.push_back({xa, y, za}), m.positions.push_back({xa + step, y, za});
      m.positions.push_back({xa, y, za + step}), m.positions.push_back({xa + step, y, za + step});
      // (a, c, b) winds counter-clockwise seen from +y: normal (c - a) x (b - a) ... points up.
      if (up) m.triangles.push_back({b, b + 2, b + 1}), m.triangles.push_back({b + 1, b + 2, b + 3});
      else m.triangles.push_back({b, b + 1, b + 2}), m.triangles.push_back({b + 1, b + 3, b + 2});
    }
}

// A ramp rising `deg` degrees along x (steeper than max_tilt_deg: not horizontal).
void add_ramp(Mesh& m, float x0, float z0, float deg) {
  const std::size_t first = m.positions.size();
  add_rect(m, x0, x0 + 0.5f, z0, z0 + 0.5f, 0.f);
  const float slope = std::tan(deg * 3.14159265f / 180.f);
  for (std::size_t i = first; i < m.positions.size(); ++i) m.positions[i].y = (m.positions[i].x - x0) * slope;
}

Mesh room() {
  Mesh m;
  add_rect(m, -1.f, 1.f, -1.f, 1.f, 0.f);              // floor, 4 m^2
  add_rect(m, -0.5f, 0.5f, 0.2f, 0.8f, 0.75f);         // desk top, 0.6 m^2, centre (0, 0.75, 0.5)
  add_rect(m, -0.5f, 0.5f, 0.2f, 0.8f, 0.72f, false);  // its underside: faces down
  add_rect(m, 0.1f, 0.4f, 0.3f, 0.6f, 0.95f);          // a box on the desk, 0.09 m^2
  add_ramp(m, -1.f, -1.6f, 30.f);                      // 30 degrees: not horizontal
  return m;
}

constexpr vec3 kUp{0.f, 1.f, 0.f};

TEST(Surfaces, FindsFloorDeskAndBoxWithTheirAreasAndHeights) {
  const std::vector<HorizontalSurface> s = find_horizontal_surfaces(room(), kUp, {{0.f, 1.5f, -1.f}});
  ASSERT_EQ(s.size(), 3u);
  // Every upward triangle is counted once: areas are exact sums (float rounding only).
  EXPECT_NEAR(s[0].area, 4.0f, 1e-3f);
  EXPECT_NEAR(s[0].height, 0.f, 1e-5f);
  EXPECT_TRUE(s[0].floor);
  EXPECT_NEAR(s[1].area, 0.6f, 1e-3f);
  EXPECT_NEAR(s[1].height, 0.75f, 1e-5f);
  EXPECT_FALSE(s[1].floor);
  EXPECT_NEAR(s[2].area, 0.09f, 1e-4f);
  EXPECT_NEAR(s[2].height, 0.95f, 1e-5f);
  // The desk's centre is its most open spot: the box covers x 0.1..0.4 of the desk's -0.5..0.5,
  // so the free part is x -0.5..0.1, z 0.2..0.8 (12 x 12 cells of 5 cm). Its middle cells are 5
  // rings (0.25 m) from the desk's edge and from the box; of those, the nearest to the desk's
  // centroid (0, 0.5) lie at x -0.225 or -0.175 and z 0.475 or 0.525 (cell means).
  EXPECT_NEAR(s[1].open_radius, 0.25f, 1e-6f);
  EXPECT_NEAR(s[1].centre.x, -0.2f, 0.026f);
  EXPECT_NEAR(s[1].centre.z, 0.5f, 0.026f);
  EXPECT_FLOAT_EQ(s[1].centre.y, s[1].height);
  EXPECT_EQ(find_floor(s), &s[0]);
  const auto support = support_surfaces(s);
  ASSERT_EQ(support.size(), 2u);
  EXPECT_EQ(support[0], &s[1]);
  EXPECT_EQ(support[1], &s[2]);
}

TEST(Surfaces, UpIsGravityNotTheWorldAxis) {
  // The same room turned 90 degrees about z: up is now -x. The floor and the desk are found as before.
  Mesh m = room();
  for (vec3& p : m.positions) p = {-p.y, p.x, p.z};
  const vec3 up{-1.f, 0.f, 0.f};
  const std::vector<HorizontalSurface> s = find_horizontal_surfaces(m, up, {{-1.5f, 0.f, -1.f}});
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s[0].area, 4.0f, 1e-3f);
  EXPECT_TRUE(s[0].floor);
  EXPECT_NEAR(s[1].height, 0.75f, 1e-5f);
}

TEST(Surfaces, ADeskSeenWithoutItsFloorIsNotTheFloor) {
  // Only the desk and the box were scanned, from 0.75 m above the desk (a camera at eye height):
  // the lowest large surface is not far enough below the camera, and nothing stands on it that
  // is furniture-high, so there is no floor and the desk is the support.
  Mesh m;
  add_rect(m, -0.5f, 0.5f, 0.2f, 0.8f, 0.75f);
  add_rect(m, 0.1f, 0.4f, 0.3f, 0.6f, 0.95f);
  const std::vector<HorizontalSurface> s = find_horizontal_surfaces(m, kUp, {{0.f, 1.5f, 0.f}});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(find_floor(s), nullptr);
  ASSERT_EQ(support_surfaces(s).size(), 2u);
  EXPECT_NEAR(support_surfaces(s)[0]->area, 0.6f, 1e-3f);
}

TEST(Surfaces, FloorSeenFromEyeHeightIsTheFloorAlone) {
  Mesh m;
  add_rect(m, -1.f, 1.f, -1.f, 1.f, -1.6f);
  const std::vector<HorizontalSurface> s = find_horizontal_surfaces(m, kUp, {{0.f, 0.f, 0.f}});
  ASSERT_EQ(s.size(), 1u);
  EXPECT_TRUE(s[0].floor);
  EXPECT_TRUE(support_surfaces(s).empty());
}

}  // namespace
}  // namespace seamless
