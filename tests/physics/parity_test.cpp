// CPU/CUDA parity of the particle solver (ctest label gpu; skipped without a CUDA device).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "core/device.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

struct SimRun {
  ParticleState state;
  SolverStats stats;
};

// Fluid in a box of scene particles, a rigid cube and a cloth falling onto it; a second cube is
// spawned at 0.05 s, so that the scene changes during the run (a CUDA graph is captured again).
SimRun run(Device dev, bool graph = true, int steps = 10, float fluid_friction = 0.f) {
  SolverParams p;
  p.cuda_graph = graph;
  p.fluid_friction = fluid_friction;
  ParticleSolver s(p, dev);
  const float d = p.particle_diameter;
  s.add_static_particles(test::static_box({-0.3f, 0.f, -0.3f}, {0.3f, 0.4f, 0.3f}, d));
  SpawnParams f;
  f.kind = SpawnKind::fluid_block, f.size = {0.2f, 0.2f, 0.2f}, f.position = {0.f, 0.15f, 0.f};
  s.spawn(f);
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {0.16f, 0.16f, 0.16f}, c.position = {0.1f, 0.4f, 0.05f},
  c.rotation = {10.f, 20.f, 0.f};
  s.spawn(c);
  SpawnParams cl;
  cl.kind = SpawnKind::cloth, cl.nx = 8, cl.ny = 8, cl.position = {-0.1f, 0.5f, 0.f};
  s.spawn(cl);
  SpawnParams late = c;
  late.time = 0.05f, late.position = {-0.15f, 0.6f, -0.1f}, late.size = {0.08f, 0.08f, 0.08f};
  s.schedule({late});
  for (int i = 0; i < steps; ++i) s.step();
  return {s.download_state(), s.stats()};
}

// Same scene, same steps on both backends. The backends differ in float rounding (FMA
// contraction, reduction order), ~1e-7 m per substep, which contacts and constraints amplify
// over 20 substeps; 1e-4 m (a 400th of a diameter) bounds that and catches any real divergence.
TEST(PhysicsParity, CpuAndCudaAgree) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  ParticleState a = run(Device::CPU).state, b = run(Device::CUDA).state;
  ASSERT_EQ(a.x.size(), b.x.size());
  float worst = 0.f;
  for (std::size_t i = 0; i < a.x.size(); ++i) worst = std::max(worst, length(a.x[i] - b.x[i]));
  std::printf("parity: largest CPU/CUDA position difference %.3g m\n", worst);
  EXPECT_LT(worst, 1e-4f);
}

// The same with solver.fluid_friction (the fluid's friction on the walls, the cube and the cloth).
TEST(PhysicsParity, CpuAndCudaAgreeWithFluidFriction) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  ParticleState a = run(Device::CPU, true, 10, 0.5f).state, b = run(Device::CUDA, true, 10, 0.5f).state;
  ASSERT_EQ(a.x.size(), b.x.size());
  float worst = 0.f;
  for (std::size_t i = 0; i < a.x.size(); ++i) worst = std::max(worst, length(a.x[i] - b.x[i]));
  std::printf("parity (fluid friction 0.5): largest CPU/CUDA position difference %.3g m\n", worst);
  EXPECT_LT(worst, 1e-4f);
}

// A fluid block large enough that CUDA runs one thread per particle (CudaExec::lanes gives 1
// lane from about 2048 threads per multiprocessor times the multiprocessors: 270k on an H200),
// whose neighbour search and pair loops take their own code path (column-major lists, batched
// gathers), which the small scene above never reaches. With solids, a rigid cube and a cloth rest
// on the block's top (a particle's gap above it, within the fluid's smoothing radius): the
// one-lane walk of rigid and cloth particles (the rigid/cloth pair test) and the pair loops of
// fluid particles with solid neighbours (Mixed), which pure fluid never takes. 5 steps of the
// falling block, the bottom layers meeting the floor. The same tolerance and reason as above
// (fewer substeps here).
ParticleState run_block(Device dev, bool with_solids) {
  SolverParams p;
  p.max_particles =
      74 * 74 * 74 + (with_solids ? 4096 : 0);  // 405,224 fluid: over the one-lane threshold of GPUs up to ~200 SMs
  ParticleSolver s(p, dev);
  const float d = p.particle_diameter;
  kernels::SceneSdf box;
  box.count = 1;
  box.prims[0] = {kernels::kSdfContainer, {0.f, 10.f, 0.f}, {2.f, 10.f, 2.f}, mat3::identity()};
  s.set_scene_sdf(box);
  SpawnParams f;
  f.kind = SpawnKind::fluid_block, f.size = {74 * d, 74 * d, 74 * d}, f.position = {0.f, 37 * d + 0.01f, 0.f};
  s.spawn(f);
  if (with_solids) {
    const float top = 74 * d + 0.01f;  // the block's top face; its top layer's centres are d/2 below
    SpawnParams c;
    c.kind = SpawnKind::rigid, c.size = {8 * d, 8 * d, 8 * d}, c.position = {0.5f, top + 4 * d + 0.5f * d, 0.f};
    s.spawn(c);
    SpawnParams cl;
    cl.kind = SpawnKind::cloth, cl.nx = 16, cl.ny = 16, cl.position = {-0.8f, top + 0.5f * d, 0.f};
    s.spawn(cl);
  }
  for (int i = 0; i < 5; ++i) s.step();
  return s.download_state();
}

void expect_block_parity(bool with_solids) {
  ParticleState a = run_block(Device::CPU, with_solids), b = run_block(Device::CUDA, with_solids);
  ASSERT_EQ(a.x.size(), b.x.size());
  ASSERT_GT(a.x.size(), 400000u);
  float worst = 0.f;
  for (std::size_t i = 0; i < a.x.size(); ++i) worst = std::max(worst, length(a.x[i] - b.x[i]));
  std::printf("parity (one lane%s): largest CPU/CUDA position difference %.3g m\n", with_solids ? ", solids" : "",
              worst);
  EXPECT_LT(worst, 1e-4f);
  if (!with_solids) return;
  // The solids' paths ran only if a solid particle was within the fluid's smoothing radius h =
  // 2 d of a fluid particle (in each other's neighbour lists): the closest such pair at the end.
  const float h = 2.f * SolverParams{}.particle_diameter;
  std::vector<vec3> solid, fluid_top;
  float top = -1e30f;
  for (std::size_t i = 0; i < b.x.size(); ++i)
    if (phase::is(b.phase[i], phase::kFluid)) top = std::max(top, b.x[i].y);
  for (std::size_t i = 0; i < b.x.size(); ++i) {
    if (!phase::is(b.phase[i], phase::kFluid)) solid.push_back(b.x[i]);
    else if (b.x[i].y > top - h) fluid_top.push_back(b.x[i]);
  }
  float closest = 1e30f;
  for (vec3 q : solid)
    for (vec3 f : fluid_top) closest = std::min(closest, length(q - f));
  EXPECT_EQ(solid.size(), 8u * 8u * 8u + 16u * 16u);
  EXPECT_LT(closest, h);
}

TEST(PhysicsParity, LargeFluidOneLaneAgrees) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  expect_block_parity(false);
}

TEST(PhysicsParity, LargeFluidWithSolidsOneLaneAgrees) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  expect_block_parity(true);
}

// A step replayed as a CUDA graph runs the same kernels in the same order on the same buffers as
// the direct launches, and every kernel is deterministic (no float atomics; the radix sort is
// stable), so the two must agree bit for bit, through the recapture after the late spawn too.
TEST(PhysicsParity, CudaGraphReplayEqualsDirectLaunches) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  SimRun g = run(Device::CUDA, true, 20), d = run(Device::CUDA, false, 20);
  ASSERT_EQ(g.state.x.size(), d.state.x.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < g.state.x.size(); ++i)
    differ += g.state.x[i].x != d.state.x[i].x || g.state.x[i].y != d.state.x[i].y ||
              g.state.x[i].z != d.state.x[i].z || g.state.v[i].x != d.state.v[i].x ||
              g.state.v[i].y != d.state.v[i].y || g.state.v[i].z != d.state.v[i].z;
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(g.stats.max_speed, d.stats.max_speed);
  EXPECT_EQ(g.stats.max_neighbours_seen, d.stats.max_neighbours_seen);
  EXPECT_EQ(g.stats.neighbour_overflow, d.stats.neighbour_overflow);
}

}  // namespace
}  // namespace seamless
