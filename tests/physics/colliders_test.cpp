// Kinematic colliders from a depth camera's view (the host oracle, host_colliders.hpp) against
// the exact geometry of a walking person's torso (a capsule, kernels/scene/movers.hpp).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.hpp"
#include "host_colliders.hpp"
#include "kernels/scene/movers.hpp"
#include "physics/builders.hpp"
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

// The vertex and normal maps (camera coordinates) the camera sees of the capsules alone (no room:
// no reading elsewhere, as a dynamic-pixel mask would leave).
struct View {
  std::vector<vec3> v, n;
};
View view_of(const mv::Scene& s) {
  const SE3 T = camera_pose();
  View out{std::vector<vec3>(static_cast<std::size_t>(kW) * kH, vec3{0.f, 0.f, 0.f}),
           std::vector<vec3>(static_cast<std::size_t>(kW) * kH, vec3{0.f, 0.f, 0.f})};
  for (int y = 0; y < kH; ++y)
    for (int x = 0; x < kW; ++x) {
      const vec3 dc = normalize(vec3{(x - 0.5f * kW) / kF, (y - 0.5f * kH) / kF, 1.f});
      const mv::Hit h = mv::raycast(s, T.t, T.rotate(dc));
      if (h.t <= 0.f) continue;
      out.v[static_cast<std::size_t>(y) * kW + x] = dc * h.t;
      out.n[static_cast<std::size_t>(y) * kW + x] = transpose(T.R) * h.normal;
    }
  return out;
}

DepthSurface surface_of(const mv::Scene& s, const std::vector<std::uint8_t>& mask = {}) {
  const View w = view_of(s);
  return depth_surface(w.v, w.n, kW, kH, camera_pose(), mask);
}

TEST(DepthColliders, PointsLieOnTheSeenSurfaceAndBehindIt) {
  // Each pixel's first point is on the capsule's surface (exact ray hit: float rounding only),
  // and the layers behind it stay on its camera ray, `spacing` apart.
  mv::Scene s;
  s.count = 1;
  s.c[0] = {{0.f, 0.2f, 0.f}, {0.f, 1.2f, 0.f}, 0.15f, 1, {1, 1, 1}};
  const std::vector<vec3> v = view_of(s).v;
  const std::size_t seen =
      static_cast<std::size_t>(std::count_if(v.begin(), v.end(), [](vec3 p) { return p.z > 0.f; }));
  ASSERT_GT(seen, 500u);  // ~19 x 84 pixels: 0.3 m x 1.3 m at 2 m, 65 pixels a metre
  const float spacing = 0.04f;
  const DepthSurface surf = surface_of(s);
  ASSERT_EQ(surf.points.size(), seen);
  const std::vector<vec3> pts = thicken(surf.points, surf.rays, spacing, 0.3f);
  ASSERT_EQ(pts.size(), seen * 8);  // floor(0.3 / 0.04) = 7 layers behind each point
  for (std::size_t i = 0; i < pts.size(); i += 8) {
    EXPECT_NEAR(mv::distance(s, pts[i]), 0.f, 1e-4f);
    const vec3 ray = normalize(pts[i] - camera_pose().t);
    for (int k = 1; k < 8; ++k) EXPECT_LT(length(pts[i + k] - (pts[i] + ray * (spacing * k))), 1e-5f);
  }
  std::vector<std::uint8_t> none(v.size(), 0);
  EXPECT_TRUE(surface_of(s, none).points.empty());
  EXPECT_THROW(depth_surface(v, v, kW - 1, kH, camera_pose()), Error);
}

TEST(DepthColliders, VelocityOfASurfaceMovingAlongItsNormal) {
  // The torso's front (the side facing the camera) moving towards it at 0.5 m/s, 1.7 cm a frame,
  // about the pixels' spacing on it: on the centre line the normal is the motion's direction, so
  // the point-to-plane velocity is the motion itself whichever previous pixel is nearest; there,
  // halfway between the frames, the colliders lie halfway.
  mv::Scene s;
  s.count = 1;
  MovingColliders mc(0.04f, 0.f, 4.f);
  const double dt = 1.0 / 30;
  for (int f = 0; f < 2; ++f) {
    const float z = 0.5f * static_cast<float>(f * dt);
    s.c[0] = {{0.f, 0.2f, z}, {0.f, 1.2f, z}, 0.15f, 1, {1, 1, 1}};
    mc.update(surface_of(s), f * dt);
  }
  const std::vector<vec3> now = mc.at(dt), half = mc.at(0.5 * dt);
  int centre = 0;
  for (std::size_t i = 0; i < now.size(); ++i) {
    // The cylinder's centre line, where the normal points at the camera (on the end caps it
    // tilts, and only the motion along it is seen, by design).
    if (std::fabs(now[i].x) > 0.01f || now[i].y < 0.3f || now[i].y > 1.1f) continue;
    ++centre;
    // Exact ray casts; the previous point's normal is off the centre line's by up to the 1 cm
    // band's angle on a 15 cm radius (4 degrees: cos 0.998) and by the curvature between the two
    // points (a pixel, ~1.5 cm: 6 degrees, cos 0.995): 1 % of the speed, 0.03 m/s allowed.
    EXPECT_NEAR(mc.velocities()[i].z, 0.5f, 0.03f) << i;
    EXPECT_NEAR(now[i].z - half[i].z, 0.5f * 0.5f * static_cast<float>(dt), 0.03f * 0.5f * static_cast<float>(dt)) << i;
  }
  EXPECT_GT(centre, 50);
}

struct Walk {
  float pushed = 0.f;   // the cube's centre along the walk, metres
  float vmax = 0.f;     // fastest particle after any step, m/s
  float worst = 1e30f;  // smallest distance of a particle centre from the torso's surface
};

// A torso (a capsule of radius 0.15 m from 0.2 to 1.2 m) walks along +x at 1 m/s through a 16 cm
// cube resting on the floor; the solver sees only what the camera sees each 1/30 s frame (3 steps
// of 0.01 s a frame), thickened by the torso's radius. interpolate: the colliders move across the
// steps with their estimated velocities (MovingColliders::at); false: they jump once a frame.
Walk walk_through_cube(bool interpolate) {
  SolverParams p;
  const float d = p.particle_diameter, r = 0.15f;
  ParticleSolver solver(p, Device::CPU);
  solver.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.5f * d));  // the floor
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {4 * d, 4 * d, 4 * d}, c.position = {0.f, 2.f * d + 0.001f, 0.f};
  solver.add_batch(make_rigid(c, p));
  for (int i = 0; i < 30; ++i) solver.step();  // settle on the floor
  const float x0 = solver.rigid_frames()[0].centre.x;
  mv::Scene s;
  s.count = 1;
  MovingColliders colliders(d, r, p.max_speed);
  Walk w;
  double t = 0.0;
  for (int frame = 0; frame < 33; ++frame) {  // 1.1 s: the torso goes from x = -0.6 to 0.5
    const float xc = -0.6f + frame / 30.f;
    s.c[0] = {{xc, 0.2f, 0.f}, {xc, 1.2f, 0.f}, r, 1, {1, 1, 1}};
    const double frame_time = t + 3 * p.dt;  // the frame's steps end at its time
    colliders.update(surface_of(s), frame_time);
    for (int k = 0; k < 3; ++k) {
      t += p.dt;
      solver.set_collider_particles(colliders.at(interpolate ? t : frame_time));
      solver.step();
      w.vmax = std::max(w.vmax, solver.stats().max_speed);
    }
    for (const vec3& x : solver.download_state().x) w.worst = std::min(w.worst, mv::distance(s, x));
  }
  w.pushed = solver.rigid_frames()[0].centre.x - x0;
  std::printf(
      "%s colliders: cube pushed %.3f m, fastest particle %.2f m/s, deepest particle centre %.4f m inside "
      "the torso\n",
      interpolate ? "moving" : "jumping", w.pushed, w.vmax, -w.worst);
  return w;
}

TEST(DepthColliders, WalkingTorsoPushesACubeAndNothingEndsInsideIt) {
  // The live colliders' physics test: a cube resting in a person's path is pushed at least 0.2 m, and no
  // particle ever ends inside the person by more than half a particle diameter.
  const float d = SolverParams{}.particle_diameter;
  const Walk moving = walk_through_cube(true), jumping = walk_through_cube(false);
  EXPECT_GE(moving.pushed, 0.2f);
  EXPECT_GE(moving.worst, -0.5f * d);
  // Pushed, not flung: the torso's front meets the cube after 0.6 - 0.15 - 0.08 = 0.37 m of its
  // 1.1 m walk, so a cube carried along ends ~0.73 m away, plus at most ~0.17 m of sliding at 1 m/s
  // against kinetic friction 0.3 once the torso has passed: at most 0.9 m. Colliders that jump
  // once a frame turn each 3.3 cm jump into a velocity over one 0.01 s step (3.3 m/s); moving them
  // with their velocities must give slower particles than that.
  EXPECT_LE(moving.pushed, 0.9f);
  EXPECT_LT(moving.vmax, jumping.vmax);
}

struct Pour {
  float worst = 1e30f;          // smallest distance of a particle centre from the torso's surface, any step
  float nearest = 1e30f;        // the same, but only of particles above the torso's axis end (landed on it)
  int on_floor = 0, total = 0;  // fluid particles at the end within three diameters of the floor
  float highest = 0.f;          // highest particle at the end, metres
};

// A person standing still (a torso capsule of radius 0.15 m from 0.2 to 1.2 m) under a 16 cm block
// of water released 0.25 m above their head, on the camera's side of the axis (the camera sees the
// front half; thickened by the radius, the colliders reach the axis plane and no further). 1.5 s
// at the solver's 0.01 s steps, the camera's surface handed over every 1/30 s as the app does.
// with_colliders false: the same without the person's colliders (the fluid falls through them).
Pour pour_on_person(bool with_colliders) {
  SolverParams p;
  const float d = p.particle_diameter, r = 0.15f;
  ParticleSolver solver(p, Device::CPU);
  solver.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.5f * d));  // the floor
  SpawnParams w;
  w.kind = SpawnKind::fluid_block, w.size = {4 * d, 4 * d, 4 * d}, w.position = {0.f, 1.2f + r + 0.25f + 2 * d, 0.06f};
  solver.add_batch(make_fluid_block(w, p));
  mv::Scene s;
  s.count = 1;
  s.c[0] = {{0.f, 0.2f, 0.f}, {0.f, 1.2f, 0.f}, r, 1, {1, 1, 1}};
  MovingColliders colliders(d, r, p.max_speed);
  Pour out;
  double t = 0.0;
  for (int frame = 0; frame < 50; ++frame) {
    const double frame_time = t + 3 * p.dt;
    if (with_colliders) colliders.update(surface_of(s), frame_time);
    for (int k = 0; k < 3; ++k) {
      t += p.dt;
      if (with_colliders) solver.set_collider_particles(colliders.at(t));
      solver.step();
      for (const vec3& x : solver.download_state().x) {
        const float dist = mv::distance(s, x);
        out.worst = std::min(out.worst, dist);
        if (x.y > 1.2f) out.nearest = std::min(out.nearest, dist);
      }
    }
  }
  for (const vec3& x : solver.download_state().x) {
    ++out.total;
    out.on_floor += x.y < 3 * d;
    out.highest = std::max(out.highest, x.y);
  }
  std::printf(
      "%s: deepest particle centre %.4f m inside the torso, nearest above its head %.4f m, %d of %d on the "
      "floor, highest %.3f m\n",
      with_colliders ? "colliders" : "no colliders", -out.worst, out.nearest, out.on_floor, out.total, out.highest);
  return out;
}

TEST(DepthColliders, WaterPouredOnAPersonRunsOffThem) {
  // Fluid poured on a person (seen by the camera, as solver.dynamic_colliders gives them
  // to the solver) lands on them, never sinks into them by more than half a particle diameter, and
  // runs off onto the floor.
  const float d = SolverParams{}.particle_diameter;
  const Pour on = pour_on_person(true), off = pour_on_person(false);
  // Landed on the head: a particle centre came within a diameter of the surface above the axis end
  // (the block falls straight onto the cap; one that missed would stay a block width away).
  EXPECT_LE(on.nearest, d);
  EXPECT_GE(on.worst, -0.5f * d);
  // Ran off: 1.5 s is twice the 0.7 s a free fall from 1.6 m takes, so all of it has reached the
  // floor unless held on the person. The floor holds 64 particles in at most a few layers, every
  // centre below three diameters; none stays up on the head or shoulders.
  EXPECT_EQ(on.on_floor, on.total);
  EXPECT_LT(on.highest, 3 * d);
  // The test can tell: without the colliders the water falls through the person.
  EXPECT_LT(off.worst, -0.5f * 0.15f);
}

}  // namespace
}  // namespace seamless
