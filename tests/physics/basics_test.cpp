// Free fall, momentum conservation, the substep rule and tunnelling (docs/PHYSICS.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

// Before any contact, a particle must follow symplectic Euler exactly: v += g dt, x += v dt,
// computed in the same float operations (the velocity update adds (p - p0) / dt = 0 exactly).
TEST(PhysicsFreeFall, EqualsSymplecticEuler) {
  SolverParams p;
  p.max_speed = 4.f;
  p.tunnel_fraction = 1.f;  // one substep: dt_sub = dt
  ParticleSolver s(p, Device::CPU);
  ASSERT_EQ(s.substeps(), 1);
  s.add_static_particles(test::static_layer(-10.f, -0.2f, 0.2f, -0.2f, 0.2f, p.particle_diameter));
  ParticleBatch b;
  b.x = {{0.1f, 1.f, -0.3f}, {0.5f, 2.f, 0.f}};
  b.v = {{0.5f, 1.f, 0.f}, {0.f, 0.f, -0.25f}};
  b.inv_mass = {1.f, 2.f};
  s.add_batch(b);
  std::vector<vec3> x = b.x, v = b.v;
  for (int step = 0; step < 30; ++step) {
    s.step();
    for (std::size_t i = 0; i < x.size(); ++i) {
      v[i] = v[i] + p.gravity * p.dt;
      x[i] = x[i] + v[i] * p.dt;
    }
    ParticleState st = s.download_state();
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_FLOAT_EQ(st.x[i].x, x[i].x);
      EXPECT_FLOAT_EQ(st.x[i].y, x[i].y);
      EXPECT_FLOAT_EQ(st.x[i].z, x[i].z);
      EXPECT_FLOAT_EQ(st.v[i].y, v[i].y);
    }
  }
  // stats() reads the largest speed from the counter write_back keeps on the device.
  EXPECT_FLOAT_EQ(s.stats().max_speed, std::max(length(v[0]), length(v[1])));
}

// No gravity, no scene: rigid cubes and a fluid blob collide. Every pairwise correction is
// equal and opposite (mass-weighted), so total momentum changes only by float rounding. In a
// position-based solver velocities are position changes over dt, so the rounding of a position
// (eps |x| ~ 3e-8 m at |x| <= 0.5 m) becomes up to 3e-5 m/s per particle and substep (dt_sub =
// 1 ms here), correlated within a rigid body; over 500 substeps as a random walk that is ~7e-4
// m/s against speeds of ~2 m/s, so 2e-4 of sum m|v|. A single unmatched contact correction would
// change momentum by ~1e-2 of sum m|v|.
TEST(PhysicsMomentum, ConservedWithoutExternalForces) {
  SolverParams p;
  p.gravity = {0.f, 0.f, 0.f};
  p.vorticity = 0.f;   // confinement adds energy by design and is not a pairwise force
  p.max_speed = 20.f;  // the speed limit is a (deliberate) external impulse: keep it out of reach
  ParticleSolver s(p, Device::CPU);
  SpawnParams a;
  a.kind = SpawnKind::rigid, a.size = {0.16f, 0.16f, 0.16f}, a.position = {-0.3f, 0.f, 0.f},
  a.velocity = {2.f, 0.f, 0.f};
  s.spawn(a);
  SpawnParams b = a;
  b.position = {0.3f, 0.05f, 0.02f}, b.velocity = {-1.f, 0.f, 0.f}, b.density = 400.f, b.rotation = {0.f, 30.f, 10.f};
  s.spawn(b);
  SpawnParams f;
  f.kind = SpawnKind::fluid_block, f.size = {0.2f, 0.2f, 0.2f}, f.position = {0.f, 0.35f, 0.f},
  f.velocity = {0.f, -2.f, 0.f};
  s.spawn(f);
  test::Momentum m0 = test::momentum(s.download_state());
  for (int i = 0; i < 50; ++i) s.step();
  ParticleState st = s.download_state();
  test::Momentum m1 = test::momentum(st);
  // The bodies must actually have collided, or the test proves nothing.
  bool collided = false;
  for (std::size_t i = 0; i < 64; ++i) collided |= std::fabs(st.v[i].x - 2.f) > 0.1f;  // cube A: 4x4x4
  EXPECT_TRUE(collided);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(m1.p[k], m0.p[k], 2e-4 * m0.magnitude_sum) << "axis " << k;
}

// Substeps keep max_speed * dt_sub <= tunnel_fraction * diameter.
TEST(PhysicsSubsteps, RuleFromSpeedLimit) {
  SolverParams p;
  p.max_speed = 8.f;  // 8 m/s * 0.01 s = 0.08 m = 2 diameters -> 4 substeps at half a diameter
  EXPECT_EQ(ParticleSolver(p, Device::CPU).substeps(), 4);
  p.substeps = 6;
  EXPECT_EQ(ParticleSolver(p, Device::CPU).substeps(), 6);
  p.substeps = 1, p.max_speed = 1.f;
  EXPECT_EQ(ParticleSolver(p, Device::CPU).substeps(), 1);
}

// A particle dropped from 2 m (6.3 m/s at impact, 1.6 diameters per 0.01 s step) onto a layer of
// scene particles one particle thick must stay above it: the substep rule makes it move at most
// half a diameter per substep, less than the 0.71 d a particle can sink over a gap of the layer
// before its contact normal points the wrong way.
TEST(PhysicsTunnelling, DropFromTwoMetresStaysAboveLayer) {
  SolverParams p;
  p.max_speed = 8.f;
  ParticleSolver s(p, Device::CPU);
  const float d = p.particle_diameter;
  s.add_static_particles(test::static_layer(0.f, -0.4f, 0.4f, -0.4f, 0.4f, d));
  ParticleBatch b;
  // Above the middle of a gap between four layer particles: the hardest place.
  b.x = {{0.5f * d, 2.f, 0.5f * d}, {0.f, 2.f, 0.1f}};
  b.v = {{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}};
  b.inv_mass = {1.f, 1.f};
  s.add_batch(b);
  for (int i = 0; i < 150; ++i) {
    s.step();
    for (const vec3& x : s.download_state().x) ASSERT_GT(x.y, 0.f) << "step " << i;
  }
  for (const vec3& x : s.download_state().x) EXPECT_NEAR(x.y, 0.7071f * d, 0.3f * d);
}

}  // namespace
}  // namespace seamless
