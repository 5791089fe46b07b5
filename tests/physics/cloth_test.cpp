// Cloth (stretch and bending constraints, Mueller 2007) dropped on a box: it must drape over the
// box without any particle entering it and without stretching its edges by more than 10 %.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "kernels/physics/scene_sdf.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

// A 0.3 m cube resting on the floor (y = 0), as analytic SDF primitives.
kernels::SceneSdf box_on_floor(float half) {
  kernels::SceneSdf s = test::half_space({0.f, 1.f, 0.f}, 0.f);
  s.count = 2;
  s.prims[1] = {kernels::kSdfBox, {0.f, half, 0.f}, {half, half, half}, mat3::identity()};
  return s;
}

// Largest relative length change over the stretch edges (structural and shear: the cloth's
// distance constraints), with the rest lengths of the flat spawn grid.
double max_edge_strain(const std::vector<vec3>& x, int nx, int ny, float sp) {
  double worst = 0.0;
  auto edge = [&](int a, int b, float rest) {
    worst = std::max(worst, std::fabs(double(length(x[a] - x[b])) / rest - 1.0));
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      int id = j * nx + i;
      if (i + 1 < nx) edge(id, id + 1, sp);
      if (j + 1 < ny) edge(id, id + nx, sp);
      if (i + 1 < nx && j + 1 < ny) {
        edge(id, id + nx + 1, sp * std::sqrt(2.f));
        edge(id + 1, id + nx, sp * std::sqrt(2.f));
      }
    }
  return worst;
}

struct DrapeRun {
  double worst_strain = 0.0, final_strain = 0.0;
  float deepest = 1e30f, lowest = 1e30f;
  int on_top = 0, on_floor = 0;
};

// A 24 x 24 cloth (0.92 m square, particle spacing = diameter) falls `height` (0.2 m) onto the
// cube (0.3 m edge), drapes over it and settles on the floor around it, 2 s simulated, checked
// every frame.
DrapeRun drape(float height = 0.2f) {
  SolverParams p;
  const float d = p.particle_diameter, half = 0.15f;
  ParticleSolver s(p, Device::CPU);
  kernels::SceneSdf sdf = box_on_floor(half);
  s.set_scene_sdf(sdf);
  SpawnParams c;
  const int n = 24;
  c.kind = SpawnKind::cloth, c.nx = n, c.ny = n, c.position = {0.01f, 2 * half + height, 0.02f};
  s.spawn(c);
  kernels::SceneSdf only_box;
  only_box.count = 1, only_box.prims[0] = sdf.prims[1];
  DrapeRun r;
  for (int f = 0; f < 200; ++f) {
    s.step();
    ParticleState st = s.download_state();
    r.worst_strain = std::max(r.worst_strain, max_edge_strain(st.x, n, n, d));
    for (const vec3& x : st.x) {
      r.deepest = std::min(r.deepest, kernels::scene_sdf(only_box, x).d);
      r.lowest = std::min(r.lowest, x.y);
    }
  }
  ParticleState st = s.download_state();
  r.final_strain = max_edge_strain(st.x, n, n, d);
  for (const vec3& x : st.x) {
    if (std::fabs(x.x) < half && std::fabs(x.z) < half && x.y > 2 * half) ++r.on_top;
    if (x.y < 0.5f * d + 0.01f) ++r.on_floor;
  }
  std::printf(
      "cloth on box from %.2f m: max edge strain %.6f (at rest %.6f), closest centre to the box %.4g m (radius %.3g), "
      "lowest %.4g m, %d particles over the top, %d on the floor\n",
      height, r.worst_strain, r.final_strain, r.deepest, 0.5f * d, r.lowest, r.on_top, r.on_floor);
  return r;
}

// No particle inside the box: the box's SDF at every cloth particle stays >= 0 at every frame
// (contacts keep centres one radius outside; a centre inside the solid means the cloth
// tunnelled), none below the floor, and it really draped: the part over the top (7 x 7 particles
// of spacing d fit in the face) stayed there, and the corners, 0.46 m from the centre and 0.3 m
// below the top, reached the floor.
TEST(PhysicsCloth, DroppedOnBoxStaysOutside) {
  DrapeRun r = drape();
  EXPECT_GE(r.deepest, 0.f);
  EXPECT_GE(r.lowest, 0.f);
  EXPECT_GE(r.on_top, 36);
  EXPECT_GT(r.on_floor, 0);
}

// Twice the drop (2.8 m/s at impact, 1.4 cm per substep): the strain limiter, which runs after the
// contacts, must not pull particles into the box (particles touching the scene count as heavier
// there). Strain is not asserted here: 4 passes leave 11 % at this impact (docs/PHYSICS.md).
TEST(PhysicsCloth, DroppedFromFortyCentimetresStaysOutside) {
  DrapeRun r = drape(0.4f);
  EXPECT_GE(r.deepest, 0.f);
  EXPECT_GE(r.lowest, 0.f);
}

// The requirement: edge strain <= 10 % at every frame (structural and shear edges). The
// cloth's default strain limit (SpawnParams::max_strain = 0.1, Provot 1995's value) is projected
// after the solver iterations in cloth_strain_passes Gauss-Seidel passes; this checks that they
// converge at the impact, where the overhang keeps falling while the top stops on the box (before
// strain limiting: 26 % there). The tolerance 1e-5 is float rounding of an edge length at these
// coordinates (positions ~0.5 m carry ~6e-8 m, relative to a 0.04 m edge ~3e-6), not slack.
TEST(PhysicsCloth, DroppedOnBoxEdgeStrainAtMostTenPercent) {
  DrapeRun r = drape();
  EXPECT_LE(r.worst_strain, 0.10 + 1e-5);
  EXPECT_LE(r.final_strain, 0.10 + 1e-5);
}

}  // namespace
}  // namespace seamless
