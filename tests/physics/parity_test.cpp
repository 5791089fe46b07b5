// CPU/CUDA parity of the particle solver (ctest label gpu; skipped without a CUDA device).
#include <gtest/gtest.h>

#include <cstdio>

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
SimRun run(Device dev, bool graph = true, int steps = 10) {
  SolverParams p;
  p.cuda_graph = graph;
  ParticleSolver s(p, dev);
  const float d = p.particle_diameter;
  s.add_static_particles(test::static_box({-0.3f, 0.f, -0.3f}, {0.3f, 0.4f, 0.3f}, d));
  SpawnParams f;
  f.kind = "fluid_block", f.size = {0.2f, 0.2f, 0.2f}, f.position = {0.f, 0.15f, 0.f};
  s.spawn(f);
  SpawnParams c;
  c.kind = "rigid", c.size = {0.16f, 0.16f, 0.16f}, c.position = {0.1f, 0.4f, 0.05f}, c.rotation = {10.f, 20.f, 0.f};
  s.spawn(c);
  SpawnParams cl;
  cl.kind = "cloth", cl.nx = 8, cl.ny = 8, cl.position = {-0.1f, 0.5f, 0.f};
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

// A fluid block large enough that CUDA runs one thread per particle (CudaExec::lanes gives 1
// lane from about 2048 threads per multiprocessor times the multiprocessors: 270k on an H200),
// whose neighbour search and pair loops take their own code path (column-major lists, batched
// gathers), which the small scene above never reaches. 5 steps of the falling block, the bottom
// layers meeting the floor. The same tolerance and reason as above (fewer substeps here).
TEST(PhysicsParity, LargeFluidOneLaneAgrees) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  const auto run_block = [](Device dev) {
    SolverParams p;
    p.max_particles = 74 * 74 * 74;  // 405,224: over the one-lane threshold of GPUs up to ~200 SMs
    ParticleSolver s(p, dev);
    const float d = p.particle_diameter;
    kernels::SceneSdf box;
    box.count = 1;
    box.prims[0] = {kernels::kSdfContainer, {0.f, 10.f, 0.f}, {2.f, 10.f, 2.f}, mat3::identity()};
    s.set_scene_sdf(box);
    SpawnParams f;
    f.kind = "fluid_block", f.size = {74 * d, 74 * d, 74 * d}, f.position = {0.f, 37 * d + 0.01f, 0.f};
    s.spawn(f);
    for (int i = 0; i < 5; ++i) s.step();
    return s.download_state();
  };
  ParticleState a = run_block(Device::CPU), b = run_block(Device::CUDA);
  ASSERT_EQ(a.x.size(), b.x.size());
  ASSERT_GT(a.x.size(), 400000u);
  float worst = 0.f;
  for (std::size_t i = 0; i < a.x.size(); ++i) worst = std::max(worst, length(a.x[i] - b.x[i]));
  std::printf("parity (one lane): largest CPU/CUDA position difference %.3g m\n", worst);
  EXPECT_LT(worst, 1e-4f);
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
    differ += g.state.x[i].x != d.state.x[i].x || g.state.x[i].y != d.state.x[i].y || g.state.x[i].z != d.state.x[i].z ||
              g.state.v[i].x != d.state.v[i].x || g.state.v[i].y != d.state.v[i].y || g.state.v[i].z != d.state.v[i].z;
  EXPECT_EQ(differ, 0u);
  EXPECT_EQ(g.stats.max_speed, d.stats.max_speed);
  EXPECT_EQ(g.stats.max_neighbours_seen, d.stats.max_neighbours_seen);
  EXPECT_EQ(g.stats.neighbour_overflow, d.stats.neighbour_overflow);
}

}  // namespace
}  // namespace seamless
