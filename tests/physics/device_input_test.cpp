// The solver takes scene and collider particles as device buffers (what
// Volume::extract_scene_particles and the depth colliders leave on the device), copied device to
// device, with the same result as the host vectors: the same points in the same order.
// DeviceInputParity: a CUDA buffer in (ctest label gpu; skipped without a CUDA device).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstddef>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

// How the static and collider points reach the solver.
enum class Input { vectors, buffers };

struct Points {
  std::vector<vec3> floor, walls, colliders;
};

// A floor, then walls appended to it (the order of the static points matters: it is kept), a
// fluid block and a rigid cube falling into the box and a slab of colliders across one corner.
Points scene_points(float d) {
  Points p;
  p.floor = test::static_layer(0.f, -0.3f, 0.3f, -0.3f, 0.3f, d);
  // The points under the fluid last (OnePointFewerIsSeen leaves the last one out).
  std::stable_sort(p.floor.begin(), p.floor.end(), [](vec3 a, vec3 b) { return length2(a) > length2(b); });
  for (vec3 q : test::static_box({-0.3f, 0.f, -0.3f}, {0.3f, 0.4f, 0.3f}, d))
    if (q.y > 0.f) p.walls.push_back(q);
  p.colliders = test::static_layer(0.1f, 0.1f, 0.3f, 0.1f, 0.3f, d);
  return p;
}

// The buffer path gets each list in a buffer on `points_dev` two points longer than the list, so
// that the count (not the buffer's size) is what must be taken.
Buffer<vec3> padded(const std::vector<vec3>& v, Device dev) {
  std::vector<vec3> longer = v;
  longer.push_back({9.f, 9.f, 9.f});
  longer.push_back({-9.f, -9.f, -9.f});
  return Buffer<vec3>::from_host(longer, dev);
}

struct SimResult {
  ParticleState state;
  SolverStats stats;
};

// drop: floor points left out of the buffer path's count (the test that the comparison can fail).
SimResult run(Device solver_dev, Input in, Device points_dev, std::int64_t drop = 0) {
  SolverParams p;
  ParticleSolver s(p, solver_dev);
  const Points pts = scene_points(p.particle_diameter);
  auto n = [](const std::vector<vec3>& v) { return static_cast<std::int64_t>(v.size()); };
  if (in == Input::vectors) {
    s.add_static_particles(pts.floor);
    s.add_static_particles(pts.walls);
    s.set_collider_particles(pts.colliders);
  } else {
    s.add_static_particles(padded(pts.floor, points_dev), n(pts.floor) - drop);
    s.add_static_particles(padded(pts.walls, points_dev), n(pts.walls));
    s.set_collider_particles(padded(pts.colliders, points_dev), n(pts.colliders));
  }
  SpawnParams f;
  f.kind = SpawnKind::fluid_block, f.size = {0.16f, 0.16f, 0.16f}, f.position = {0.f, 0.2f, 0.f};
  s.spawn(f);
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {0.12f, 0.12f, 0.12f}, c.position = {0.15f, 0.35f, 0.15f};
  s.spawn(c);
  for (int i = 0; i < 30; ++i) s.step();
  return {s.download_state(), s.stats()};
}

// Every kernel of the solver is deterministic on either backend (no float atomics, a stable sort;
// PhysicsParity.CudaGraphReplayEqualsDirectLaunches), so the same static points in the same order
// give the same state bit for bit; a point missing, added or moved in the static order changes
// the neighbour sums and so the positions.
std::size_t differing(const SimResult& a, const SimResult& b) {
  EXPECT_EQ(a.state.x.size(), b.state.x.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(a.state.x.size(), b.state.x.size()); ++i)
    differ += a.state.x[i].x != b.state.x[i].x || a.state.x[i].y != b.state.x[i].y ||
              a.state.x[i].z != b.state.x[i].z || a.state.v[i].x != b.state.v[i].x ||
              a.state.v[i].y != b.state.v[i].y || a.state.v[i].z != b.state.v[i].z;
  return differ;
}

TEST(DeviceInput, BuffersGiveTheSameSolverStateAsVectors) {
  const SimResult a = run(Device::CPU, Input::vectors, Device::CPU);
  const SimResult b = run(Device::CPU, Input::buffers, Device::CPU);
  const Points pts = scene_points(SolverParams{}.particle_diameter);
  EXPECT_EQ(b.stats.static_particles, static_cast<std::int64_t>(pts.floor.size() + pts.walls.size()));
  EXPECT_EQ(b.stats.collider_particles, static_cast<std::int64_t>(pts.colliders.size()));
  EXPECT_EQ(a.stats.static_particles, b.stats.static_particles);
  EXPECT_EQ(differing(a, b), 0u);
  EXPECT_EQ(a.stats.max_speed, b.stats.max_speed);
  EXPECT_EQ(a.stats.max_static_neighbours_seen, b.stats.max_static_neighbours_seen);
}

// The test can tell: the fluid and the cube touch the static points within the steps, and one
// floor point fewer (the count one short) gives another state.
TEST(DeviceInput, OnePointFewerIsSeen) {
  const SimResult a = run(Device::CPU, Input::buffers, Device::CPU);
  EXPECT_GT(a.stats.max_static_neighbours_seen, 0);
  EXPECT_GT(differing(a, run(Device::CPU, Input::buffers, Device::CPU, 1)), 0u);
}

TEST(DeviceInput, ACountOverTheBufferIsAnError) {
  ParticleSolver s(SolverParams{}, Device::CPU);
  const Buffer<vec3> b = Buffer<vec3>::from_host({{0.f, 0.f, 0.f}}, Device::CPU);
  EXPECT_THROW(s.add_static_particles(b, 2), Error);
  EXPECT_THROW(s.set_collider_particles(b, -1), Error);
}

// CUDA buffers in: to a CUDA solver (device to device) the same as host vectors to it, and to a
// CPU solver (device to host) the same as host vectors to that.
TEST(DeviceInputParity, CudaBuffersGiveTheSameSolverStateAsVectors) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  EXPECT_EQ(differing(run(Device::CUDA, Input::vectors, Device::CPU), run(Device::CUDA, Input::buffers, Device::CUDA)),
            0u);
  EXPECT_EQ(differing(run(Device::CPU, Input::vectors, Device::CPU), run(Device::CPU, Input::buffers, Device::CUDA)),
            0u);
}

}  // namespace
}  // namespace seamless
