// CPU/CUDA parity of the particle solver (ctest label gpu; skipped without a CUDA device).
#include <gtest/gtest.h>

#include <cstdio>

#include "core/device.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

ParticleState run(Device dev) {
  SolverParams p;
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
  for (int i = 0; i < 10; ++i) s.step();
  return s.download_state();
}

// Same scene, same steps on both backends. The backends differ in float rounding (FMA
// contraction, reduction order), ~1e-7 m per substep, which contacts and constraints amplify
// over 20 substeps; 1e-4 m (a 400th of a diameter) bounds that and catches any real divergence.
TEST(PhysicsParity, CpuAndCudaAgree) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  ParticleState a = run(Device::CPU), b = run(Device::CUDA);
  ASSERT_EQ(a.x.size(), b.x.size());
  float worst = 0.f;
  for (std::size_t i = 0; i < a.x.size(); ++i) worst = std::max(worst, length(a.x[i] - b.x[i]));
  std::printf("parity: largest CPU/CUDA position difference %.3g m\n", worst);
  EXPECT_LT(worst, 1e-4f);
}

}  // namespace
}  // namespace seamless
