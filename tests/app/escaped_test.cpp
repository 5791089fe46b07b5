// summary.json's escaped particles (src/app/escaped.cpp) on a scan made by hand: a desk top at
// height 0 over a floor at -0.7 with a hole in it, and a wall. A splash on the desk and water at
// rest under it stay in the scene; a particle through the desk, one falling through the floor's
// hole with no floor plane, one under the floor and one beside the scan count, each in its class.
#include <gtest/gtest.h>

#include "app/escaped.hpp"

namespace seamless {
namespace {

constexpr float kD = 0.02f;     // particle diameter
constexpr float kStep = 0.01f;  // vertex spacing (a 1 cm voxel)

// Up-facing vertices on [x0, x1] x [z0, z1] at height y, leaving out x in (hole0, hole1).
void add_plane(Mesh& m, float y, float x0, float x1, float z0, float z1, float hole0 = 1e9f, float hole1 = 1e9f) {
  for (float x = x0; x <= x1 + 1e-6f; x += kStep)
    for (float z = z0; z <= z1 + 1e-6f; z += kStep) {
      if (x > hole0 && x < hole1) continue;
      m.positions.push_back({x, y, z});
      m.normals.push_back({0.f, 1.f, 0.f});
    }
}

Mesh desk_scan() {
  Mesh m;
  add_plane(m, 0.f, -0.3f, 0.3f, -0.3f, 0.3f);                // the desk top
  add_plane(m, -0.7f, -0.6f, 0.6f, -0.6f, 0.6f, 0.4f, 0.5f);  // the floor, a 10 cm hole at x in (0.4, 0.5)
  for (float y = 0.f; y <= 0.5f + 1e-6f; y += kStep)          // a wall at the desk's back, facing +x
    for (float z = -0.3f; z <= 0.3f + 1e-6f; z += kStep) {
      m.positions.push_back({-0.3f, y, z});
      m.normals.push_back({1.f, 0.f, 0.f});
    }
  return m;
}

ParticleState one(vec3 x, vec3 v) {
  ParticleState s;
  s.x = {x}, s.v = {v}, s.inv_mass = {1.f}, s.phase = {0u};
  return s;
}

app::EscapedParticles escaped(vec3 x, vec3 v, bool floor_plane) {
  const Mesh m = desk_scan();
  const app::SceneBounds b =
      app::mesh_bounds(m, {0.f, 1.f, 0.f}, floor_plane ? std::optional<float>(-0.7f) : std::nullopt);
  return app::count_escaped(one(x, v), b, m, kD);
}

const vec3 kDown{0.f, -0.8f, 0.f};  // faster than kFallSpeed: the real run's splash moved at 0.79 m/s

TEST(Escaped, SplashOnTheSurfaceStays) {
  for (bool fp : {true, false}) {
    // Moving down with its centre 6 mm into the desk (the real run's splash), and a radius above it.
    EXPECT_EQ(escaped({0.05f, -0.006f, 0.05f}, kDown, fp).total(), 0) << fp;
    EXPECT_EQ(escaped({0.05f, 0.01f, 0.05f}, kDown, fp).total(), 0) << fp;
    // Less than a diameter below the surface: not yet through it.
    EXPECT_EQ(escaped({0.05f, -0.9f * kD, 0.05f}, kDown, fp).total(), 0) << fp;
    // In the air over the desk (thrown up, coming down), and falling beside a wall.
    EXPECT_EQ(escaped({0.05f, 0.2f, 0.05f}, kDown, fp).total(), 0) << fp;
    EXPECT_EQ(escaped({-0.295f, 0.2f, 0.05f}, kDown, fp).total(), 0) << fp;
  }
}

TEST(Escaped, AtRestUnderAnOverhangStays) {
  for (bool fp : {true, false}) EXPECT_EQ(escaped({0.05f, -0.69f, 0.05f}, {0.f, 0.f, 0.f}, fp).total(), 0) << fp;
}

TEST(Escaped, FallingOffTheEdgeOntoTheFloorStays) {
  for (bool fp : {true, false}) EXPECT_EQ(escaped({0.35f, -0.2f, 0.05f}, kDown, fp).total(), 0) << fp;
}

TEST(Escaped, ThroughTheSurfaceCounts) {
  for (bool fp : {true, false}) {
    // More than a diameter below the desk top, straight under it, moving down: it went through.
    EXPECT_EQ(escaped({0.05f, -1.1f * kD, 0.05f}, kDown, fp).falling, 1) << fp;
    EXPECT_EQ(escaped({0.05f, -0.3f, 0.05f}, kDown, fp).falling, 1) << fp;
    // Just over the falling speed, the same.
    EXPECT_EQ(escaped({0.05f, -0.3f, 0.05f}, {0.f, -1.01f * app::kFallSpeed, 0.f}, fp).falling, 1) << fp;
  }
}

TEST(Escaped, FallingThroughAHoleCountsWithoutAFloorPlane) {
  // Over the floor's hole: nothing under it in the scan. A floor plane catches it.
  EXPECT_EQ(escaped({0.45f, -0.2f, 0.05f}, kDown, false).falling, 1);
  EXPECT_EQ(escaped({0.45f, -0.2f, 0.05f}, kDown, true).total(), 0);
}

TEST(Escaped, BelowTheFloorAndOutsideCount) {
  EXPECT_EQ(escaped({0.05f, -0.7f - 2.5f * kD, 0.05f}, {0.f, 0.f, 0.f}, true).below_floor, 1);
  EXPECT_EQ(escaped({0.6f + 2.5f * kD, -0.5f, 0.05f}, {0.f, 0.f, 0.f}, true).outside, 1);
  // Without a floor plane the one under the floor is outside the scan's bounds instead.
  EXPECT_EQ(escaped({0.05f, -0.7f - 2.5f * kD, 0.05f}, {0.f, 0.f, 0.f}, false).outside, 1);
}

}  // namespace
}  // namespace seamless
