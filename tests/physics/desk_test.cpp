// Fluid poured onto the synthetic room's desk, represented by static scene particles sampled
// from the room's analytic SDF (kernels/scene/synthetic_room.hpp; world z up, floor at z = 0).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "kernels/scene/synthetic_room.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

namespace R = kernels::room;

// Scene particles of the desk and what stands on it: a lattice of spacing d aligned with the
// desk top's centre plane (z = 0.73 m, one radius below the 0.75 m top face of the 4 cm slab),
// keeping the points inside the solid by at most one diameter (a shell one lattice step thick,
// so neighbouring points are at most sqrt(3) d apart and no particle of diameter d fits through).
std::vector<vec3> desk_particles(float d) {
  std::vector<vec3> out;
  const vec3 c = R::desk_centre();
  const float zc = R::kDeskTopZ - 0.5f * d;
  for (int k = -18; k <= 7; ++k)
    for (int j = -10; j <= 10; ++j)
      for (int i = -19; i <= 19; ++i) {
        vec3 p{c.x + i * d, c.y + j * d, zc + k * d};
        if (p.z <= 0.f) continue;
        float s = R::room_sdf(p);
        if (s < 0.f && s >= -d) out.push_back(p);
      }
  return out;
}

// A jet (nozzle radius 10 cm: discs of 21 particles, 2 m/s down, 1000 particles/s for 1.5 s) falls 0.2 m onto the desk
// top 0.15 m from its front edge (y = 0.25 m), beside the objects on the desk; 3 s simulated. The floor is the room's
// floor plane (a half-space SDF at z = 0; the desk is only particles). Expected from the geometry:
// - pooling: fluid at rest on the top sits on the scene layer at z = 0.73: directly above a scene
//   particle at 0.73 + d = 0.77 (desk top + radius), over the gap between four at
//   0.73 + 0.71 d = 0.758; so the first layer lies in [0.75, 0.75 + 2r] over the desk's footprint;
// - flowing off: fluid beyond the desk's outline (|x| > 0.7 or y outside [0.25, 0.95]) near the
//   floor (z < 2 d);
// - none inside the desk: no fluid centre inside the desk top slab or legs (room primitives 1-5).
TEST(PhysicsDesk, FluidPouredOnDeskPoolsAndFlowsOffTheEdge) {
  SolverParams p;
  p.gravity = R::gravity();
  p.max_speed = 4.f;
  const float d = p.particle_diameter, r = 0.5f * d;
  ParticleSolver s(p, Device::CPU);
  std::vector<vec3> desk = desk_particles(d);
  ASSERT_GT(desk.size(), 600u);  // at least the 35 x 18 lattice of the top
  s.add_static_particles(desk);
  s.set_scene_sdf(test::half_space({0.f, 0.f, 1.f}, 0.f));
  SpawnParams e;
  e.kind = SpawnKind::emitter, e.position = {0.45f, 0.40f, 0.95f}, e.velocity = {0.f, 0.f, -2.f};
  e.rate = 1000.f, e.duration = 1.5f, e.nozzle_radius = 0.1f;
  s.spawn(e);
  auto inside_desk = [](vec3 x) {
    for (int i = 1; i <= 5; ++i)
      if (R::primitive_sdf(R::primitive(i), x).d < 0.f) return true;
    return false;
  };
  int inside = 0;
  for (int f = 0; f < 300; ++f) {
    s.step();
    if (f % 10 != 9) continue;
    ParticleState st = s.download_state();
    for (const vec3& x : st.x) inside += inside_desk(x) ? 1 : 0;
  }
  ParticleState st = s.download_state();
  int pooled = 0, off = 0, total = static_cast<int>(st.x.size());
  for (const vec3& x : st.x) {
    bool over = std::fabs(x.x) < 0.7f && x.y > 0.25f && x.y < 0.95f;
    if (over && x.z >= R::kDeskTopZ && x.z <= R::kDeskTopZ + 2 * r) ++pooled;
    if (!over && x.z < 2 * d) ++off;
  }
  std::printf(
      "desk: %d fluid particles, %d pooled on the top, %d on the floor beyond the edge, %d samples "
      "inside the desk, %zu scene particles\n",
      total, pooled, off, inside, desk.size());
  EXPECT_EQ(inside, 0);
  EXPECT_GT(pooled, 50);
  EXPECT_GT(off, 50);
}

}  // namespace
}  // namespace seamless
