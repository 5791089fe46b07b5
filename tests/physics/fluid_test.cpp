// Position Based Fluids: a fluid at rest keeps its density; a dam break against Martin & Moyce.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

#include "core/cpu_simd.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

struct RestResult {
  double mean_err = 0, max_err = 0;
  int interior = 0;
  int escaped = 0;
  vec3 escaped_at{0.f, 0.f, 0.f};
};

// A W x 25 x W block on the cubic rest lattice in an open box of scene particles, settled for
// 2 s. Interior = at least h from the walls, the floor and the free surface (where the kernel
// sum is truncated and the unilateral constraint lets density fall below rho_0 by design).
RestResult fluid_at_rest(int iterations, int W) {
  SolverParams p;
  p.iterations = iterations;
  const float d = p.particle_diameter, h = p.fluid_smoothing * d;
  const int H = 25;
  ParticleSolver s(p, Device::CPU);
  s.add_static_particles(test::static_box({-d, 0.f, -d}, {W * d, (H + 5) * d, W * d}, d));
  SpawnParams f;
  f.kind = SpawnKind::fluid_block;
  f.size = {W * d, H * d, W * d};
  f.position = {(W - 1) * d / 2, d + (H - 1) * d / 2, (W - 1) * d / 2};
  s.spawn(f);
  for (int i = 0; i < 200; ++i) s.step();
  ParticleState st = s.download_state();
  std::vector<float> ratio = s.fluid_density_ratio();
  float top = -1e9f;
  for (const vec3& x : st.x) top = std::max(top, x.y);
  RestResult r;
  for (std::size_t k = 0; k < st.x.size(); ++k) {
    vec3 x = st.x[k];
    // Inside the walls' particle centres (at -d and W d) and above the floor's (at 0).
    if (!(x.x > -d && x.z > -d && x.x < W * d && x.z < W * d && x.y > 0.f && x.y < (H + 5) * d)) {
      ++r.escaped;
      r.escaped_at = x;
    }
    float lo = h - 0.5f * d, hi = (W - 1) * d - h + 0.5f * d;
    if (x.x < lo || x.z < lo || x.x > hi || x.z > hi || x.y < d + h || x.y > top - h) continue;
    double e = std::fabs(ratio[k] - 1.0);
    r.mean_err += e;
    r.max_err = std::max(r.max_err, e);
    ++r.interior;
  }
  r.mean_err /= std::max(r.interior, 1);
  return r;
}

// Acceptance thresholds of the fluid solver (4 iterations): mean interior density error <= 2 %, max <= 5 %.
TEST(PhysicsFluid, AtRestInBoxKeepsDensity) {
  RestResult r = fluid_at_rest(4, 8);
  std::printf("fluid at rest, 4 iterations: interior %d, mean |rho/rho0 - 1| %.4f, max %.4f\n", r.interior, r.mean_err,
              r.max_err);
  ASSERT_GT(r.interior, 100);
  EXPECT_LE(r.mean_err, 0.02);
  EXPECT_LE(r.max_err, 0.05);
  EXPECT_EQ(r.escaped, 0) << "e.g. at " << r.escaped_at.x << " " << r.escaped_at.y << " " << r.escaped_at.z;
  // The dissertation's 2 iterations: reported only (docs/PHYSICS.md).
  RestResult r2 = fluid_at_rest(2, 8);
  std::printf(
      "fluid at rest, 2 iterations: interior %d, mean |rho/rho0 - 1| %.4f, max %.4f, %d left the box "
      "(e.g. at %.3f %.3f %.3f)\n",
      r2.interior, r2.mean_err, r2.max_err, r2.escaped, r2.escaped_at.x, r2.escaped_at.y, r2.escaped_at.z);
}

// Martin & Moyce 1952 (plate 2, water column of width a, height 2a): surge front x/a against
// T = t sqrt(2 g / a).
const double kMartinMoyce[][2] = {{0.41, 1.11}, {0.84, 1.22}, {1.19, 1.44}, {1.43, 1.67}, {1.63, 1.89},
                                  {1.83, 2.11}, {1.98, 2.33}, {2.20, 2.56}, {2.32, 2.78}, {2.51, 3.00},
                                  {2.65, 3.22}, {2.83, 3.44}, {2.98, 3.67}, {3.11, 3.89}, {3.33, 4.11}};

// Column a = 25 diameters (1 m) wide and 2a high in a 2-particle slab between smooth walls (a
// container SDF: a particle floor's bumps would act as friction the experiment did not have).
// The front is the leading particle's edge. Acceptance tolerance 15 %, for 1 <= T <= 3.
TEST(PhysicsFluid, DamBreakFollowsMartinMoyce) {
  SolverParams p;
  p.max_speed = 10.f;  // the surge reaches ~6 m/s
  const float d = p.particle_diameter, a = 25 * d, g = std::fabs(p.gravity.y);
  const int Z = 2;
  ParticleSolver s(p, Device::CPU);
  kernels::SceneSdf sdf;
  sdf.count = 1;
  sdf.prims[0] = {kernels::kSdfContainer, {3 * a, 1.5f * a, Z * d / 2}, {3 * a, 1.5f * a, Z * d / 2}, mat3::identity()};
  s.set_scene_sdf(sdf);
  SpawnParams f;
  f.kind = SpawnKind::fluid_block;
  f.size = {a, 2 * a, Z * d};
  f.position = {a / 2, a, Z * d / 2};
  s.spawn(f);
  const double tscale = std::sqrt(2.0 * g / a);
  std::vector<double> T{0.0}, X{1.0};
  while (T.back() < 3.1) {
    s.step();
    float front = 0.f;
    for (const vec3& x : s.download_state().x) front = std::max(front, x.x + 0.5f * d);
    T.push_back(s.stats().time * tscale);
    X.push_back(front / a);
  }
  int checked = 0;
  for (const auto& m : kMartinMoyce) {
    if (m[0] < 1.0 || m[0] > 3.0) continue;
    auto it = std::lower_bound(T.begin(), T.end(), m[0]);
    std::size_t i = static_cast<std::size_t>(it - T.begin());
    double u = (m[0] - T[i - 1]) / (T[i] - T[i - 1]);
    double x = X[i - 1] + u * (X[i] - X[i - 1]);
    std::printf("dam break T %.2f: x/a %.3f, Martin & Moyce %.2f (%+.1f %%)\n", m[0], x, m[1], 100 * (x / m[1] - 1));
    EXPECT_NEAR(x, m[1], 0.15 * m[1]) << "T = " << m[0];
    ++checked;
  }
  EXPECT_EQ(checked, 11);
}

// The CPU's SIMD tiles (8 particles a vector, core/simd.hpp) do the scalar loops'
// float operations in the scalar order, lane by lane, so the states must be equal bit for bit.
// Scene 1 mixes tiles that take the vector path (fluid with fluid-only lists) with tiles that
// decline (fluid next to static walls, a rigid cube that falls into the fluid, the cube); scene
// 2 (a fluid block in an SDF box, no static particles) also takes find_neighbors' tiles.
// solver.fluid_friction: a fluid particle sliding over a floor at v0 = 1 m/s. Position-based
// friction (Macklin 2014, section 6.1) takes up to mu times the contact depth off the tangential
// motion each substep; resting on the floor that depth is g dt^2 per substep, so the particle
// decelerates at mu g (Coulomb) and stops after v0^2 / (2 mu g) = 0.102 m for mu = 0.5. The
// discrete stop errs by at most one substep's travel (v0 dt / substeps = 5 mm) plus the last
// static capture, hence 1.5 cm. Without it (0, the default) the particle keeps its speed.
double slide_distance(float mu, float seconds) {
  SolverParams p;
  p.fluid_friction = mu;
  ParticleSolver s(p, Device::CPU);
  s.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.f));
  ParticleBatch b;
  b.kind = ParticleBatch::kFluid;
  b.x = {{0.f, 0.5f * p.particle_diameter, 0.f}};
  b.v = {{1.f, 0.f, 0.f}};
  b.inv_mass = {1.f};
  s.add_batch(b);
  for (int i = 0; i < static_cast<int>(std::lround(seconds / p.dt)); ++i) s.step();
  return s.download_state().x[0].x;
}

TEST(PhysicsFluid, FrictionOnTheSceneStopsASlideAtCoulombsDistance) {
  EXPECT_NEAR(slide_distance(0.5f, 0.5f), 1.0 / (2 * 0.5 * 9.81), 0.015);
  EXPECT_NEAR(slide_distance(0.f, 0.5f), 0.5, 0.01);  // slips: 1 m/s for 0.5 s
}

TEST(FluidSimd, TilesGiveTheScalarLoopsStatesBitForBit) {
  if (!simd::cpu_simd()) GTEST_SKIP() << "this CPU has no AVX2: the SIMD tiles do not run";
  auto run = [](bool simd, bool walls) {
    simd::set_cpu_simd(simd);
    SolverParams p;
    const float d = p.particle_diameter;
    const int W = 13, H = 11;  // 1859 fluid particles: the last tile is partial (scalar loops)
    ParticleSolver s(p, Device::CPU);
    if (walls) s.add_static_particles(test::static_box({-d, 0.f, -d}, {W * d, (H + 8) * d, W * d}, d));
    else s.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.f));
    SpawnParams f;
    f.kind = SpawnKind::fluid_block;
    f.size = {W * d, H * d, W * d};
    f.position = {(W - 1) * d / 2, d + (H - 1) * d / 2, (W - 1) * d / 2};
    s.spawn(f);
    SpawnParams c;
    c.kind = SpawnKind::rigid;
    c.size = {4 * d, 4 * d, 4 * d};
    c.position = {(W - 1) * d / 2, (H + 4) * d, (W - 1) * d / 2};
    if (walls) s.spawn(c);
    for (int i = 0; i < 40; ++i) s.step();
    return s.download_state();
  };
  for (bool walls : {true, false}) {
    const ParticleState a = run(true, walls), b = run(false, walls);
    simd::set_cpu_simd(true);
    ASSERT_EQ(a.x.size(), b.x.size());
    EXPECT_EQ(std::memcmp(a.x.data(), b.x.data(), a.x.size() * sizeof(vec3)), 0) << "walls " << walls;
    EXPECT_EQ(std::memcmp(a.v.data(), b.v.data(), a.v.size() * sizeof(vec3)), 0) << "walls " << walls;
    // The scene did move (the comparison is not of two resting states).
    float vmax = 0.f;
    for (const vec3& v : a.v) vmax = std::max(vmax, length(v));
    EXPECT_GT(vmax, 0.05f) << "walls " << walls;
  }
}

}  // namespace
}  // namespace seamless
