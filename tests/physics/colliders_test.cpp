// Issue 22: kinematic colliders from a depth camera's view (physics/depth_colliders.hpp) against
// the exact geometry of a walking person's torso (a capsule, kernels/scene/movers.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.hpp"
#include "kernels/scene/movers.hpp"
#include "physics/builders.hpp"
#include "physics/depth_colliders.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

namespace mv = kernels::movers;

// A 160x120 camera (the Kinect's pyramid level 2: f = 517 / 4) 2 m in front of the scene at
// torso height, looking along world -z (y up in the physics tests): camera x = world x, camera
// y (down) = world -y, camera z = world -z.
constexpr int kW = 160, kH = 120;
constexpr float kF = 129.3f;
SE3 camera_pose() {
  SE3 T = SE3::identity();
  T.R.m[1][1] = -1.f, T.R.m[2][2] = -1.f;
  T.t = {0.f, 0.7f, 2.f};
  return T;
}

// The vertex map (camera coordinates) the camera sees of the capsules alone (no room: no reading
// elsewhere, as a dynamic-pixel mask would leave).
std::vector<vec3> view_of(const mv::Scene& s) {
  const SE3 T = camera_pose();
  std::vector<vec3> v(static_cast<std::size_t>(kW) * kH, vec3{0.f, 0.f, 0.f});
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const vec3 dc = normalize(vec3{(x - 0.5f * kW) / kF, (y - 0.5f * kH) / kF, 1.f});
      const mv::Hit h = mv::raycast(s, T.t, T.rotate(dc));
      if (h.t > 0.f) v[static_cast<std::size_t>(y) * kW + x] = dc * h.t;
    }
  return v;
}

TEST(DepthColliders, PointsLieOnTheSeenSurfaceAndBehindIt) {
  // Each pixel's first point is on the capsule's surface (exact ray hit: float rounding only),
  // and the layers behind it stay on its camera ray, `spacing` apart.
  mv::Scene s;
  s.count = 1;
  s.c[0] = {{0.f, 0.2f, 0.f}, {0.f, 1.2f, 0.f}, 0.15f, 1, {1, 1, 1}};
  const std::vector<vec3> v = view_of(s);
  const std::size_t seen = static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [](vec3 p) { return p.z > 0.f; }));
  ASSERT_GT(seen, 500u);  // ~19 x 84 pixels: 0.3 m x 1.3 m at 2 m, 65 pixels a metre
  const float spacing = 0.04f;
  const std::vector<vec3> pts = depth_collider_points(v, kW, kH, camera_pose(), spacing, 0.3f);
  ASSERT_EQ(pts.size(), seen * 8);  // floor(0.3 / 0.04) = 7 layers behind each point
  for (std::size_t i = 0; i < pts.size(); i += 8) {
    EXPECT_NEAR(mv::distance(s, pts[i]), 0.f, 1e-4f);
    const vec3 ray = normalize(pts[i] - camera_pose().t);
    for (int k = 1; k < 8; ++k) EXPECT_LT(length(pts[i + k] - (pts[i] + ray * (spacing * k))), 1e-5f);
  }
  std::vector<std::uint8_t> none(v.size(), 0);
  EXPECT_TRUE(depth_collider_points(v, kW, kH, camera_pose(), spacing, 0.3f, none).empty());
  EXPECT_THROW(depth_collider_points(v, kW - 1, kH, camera_pose(), spacing, 0.3f), Error);
}

TEST(DepthColliders, WalkingTorsoPushesACubeAndNothingEndsInsideIt) {
  // Issue 22's physics test: a cube resting in a person's path is pushed at least 0.2 m, and no
  // particle ever ends inside the person by more than half a particle diameter. The torso (a
  // capsule of radius 0.15 m from 0.2 to 1.2 m) walks along +x at 1 m/s through the cube; the
  // solver sees only what the camera sees each 1/30 s frame (3 steps of 0.01 s a frame).
  SolverParams p;
  const float d = p.particle_diameter;
  ParticleSolver solver(p, Device::CPU);
  solver.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.5f * d));  // the floor
  SpawnParams c;
  c.kind = "rigid", c.size = {4 * d, 4 * d, 4 * d}, c.position = {0.f, 2.f * d + 0.001f, 0.f};
  solver.add_batch(make_rigid(c, p));
  for (int i = 0; i < 30; ++i) solver.step();  // settle on the floor
  const float x0 = solver.rigid_frames()[0].centre.x;
  mv::Scene s;
  s.count = 1;
  const float r = 0.15f;
  float worst = 1e30f;  // smallest distance of a particle centre from the torso's surface
  for (int frame = 0; frame < 33; ++frame) {  // 1.1 s: the torso goes from x = -0.6 to 0.5
    const float xc = -0.6f + frame / 30.f;
    s.c[0] = {{xc, 0.2f, 0.f}, {xc, 1.2f, 0.f}, r, 1, {1, 1, 1}};
    solver.set_collider_particles(depth_collider_points(view_of(s), kW, kH, camera_pose(), d, 2 * r));
    for (int k = 0; k < 3; ++k) solver.step();
    for (const vec3& x : solver.download_state().x) worst = std::min(worst, mv::distance(s, x));
  }
  const float pushed = solver.rigid_frames()[0].centre.x - x0;
  std::printf("cube pushed %.3f m; deepest particle centre %.4f m inside the torso\n", pushed, -worst);
  EXPECT_GE(pushed, 0.2f);
  EXPECT_GE(worst, -0.5f * d);
}

}  // namespace
}  // namespace seamless
