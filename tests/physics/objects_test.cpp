// The solver's object model (physics/objects.hpp, ParticleSolver::objects): what spawns when, which
// particles each object holds with its spawn entry and rest offsets, and objects.txt round trips.
// A few steps of a tiny scene: it runs in well under a second.
#include <gtest/gtest.h>

#include <filesystem>

#include "physics/particle_io.hpp"
#include "physics/particle_solver.hpp"

namespace seamless::test {
namespace {

SpawnParams rigid_at(float time, RigidShape shape) {
  SpawnParams s;
  s.kind = SpawnKind::rigid, s.shape = shape, s.time = time;
  s.size = {0.1f, 0.1f, 0.1f};
  s.position = {0.f, 1.f, 0.f};
  return s;
}

// Entries spawn at the start of the first step whose start time reaches theirs, in list order;
// each object keeps its index in the list (the order of creation is not the list's order here),
// its particle range and the builder's rest offsets (exactly: they are copied).
TEST(SolverObjects, ScheduleOrderSpawnIndexAndRest) {
  SolverParams p;
  p.particle_diameter = 0.05f, p.dt = 0.01f, p.gravity = {0.f, 0.f, 0.f};
  ParticleSolver s(p, Device::CPU);
  SpawnParams cloth;
  cloth.kind = SpawnKind::cloth, cloth.nx = 3, cloth.ny = 2, cloth.time = 0.005f, cloth.position = {1.f, 1.f, 0.f};
  // 0.02 s falls in the third step (starts 0, 0.01, 0.02): spawned then; 0.015 in the third too.
  s.schedule(
      {rigid_at(0.02f, RigidShape::box), cloth, rigid_at(0.f, RigidShape::sphere), rigid_at(0.015f, RigidShape::box)});
  s.step();
  ASSERT_EQ(s.objects().bodies.size(), 1u);
  EXPECT_EQ(s.objects().bodies[0].spawn, 2);
  EXPECT_NE(s.objects().bodies[0].mesh, nullptr);  // a sphere is drawn as one
  EXPECT_EQ(s.objects().cloths.size(), 0u);
  s.step();
  ASSERT_EQ(s.objects().cloths.size(), 1u);
  EXPECT_EQ(s.objects().cloths[0].spawn, 1);
  EXPECT_EQ(s.objects().cloths[0].count, 6);
  EXPECT_EQ(s.objects().cloths[0].triangles.size(), 4u);  // 2 x 1 quads, two triangles each
  s.step();
  ASSERT_EQ(s.objects().bodies.size(), 3u);
  EXPECT_EQ(s.objects().bodies[1].spawn, 0);  // list order among entries due at one step
  EXPECT_EQ(s.objects().bodies[2].spawn, 3);
  EXPECT_EQ(s.objects().bodies[1].mesh, nullptr);  // a box: drawn as the box around its rest offsets
  EXPECT_EQ(s.pending_spawns(), 0u);
  const ParticleBatch b = make_rigid(rigid_at(0.f, RigidShape::box), p);
  const RigidBody& body = s.objects().bodies[1];
  EXPECT_EQ(body.first, s.objects().bodies[0].count + 6);
  ASSERT_EQ(body.count, b.size());
  for (std::int64_t i = 0; i < body.count; ++i) EXPECT_EQ(length(body.rest[i] - b.rest[i]), 0.f);
  const std::vector<RigidFrame> frames = s.rigid_frames();
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(frames[1].first, body.first);
}

// spawn_next (the window's key G) takes the earliest pending entry now, with its index.
TEST(SolverObjects, SpawnNextTakesTheEarliest) {
  SolverParams p;
  p.particle_diameter = 0.05f;
  ParticleSolver s(p, Device::CPU);
  s.schedule({rigid_at(2.f, RigidShape::box), rigid_at(1.f, RigidShape::sphere)});
  s.spawn_next();
  ASSERT_EQ(s.objects().bodies.size(), 1u);
  EXPECT_EQ(s.objects().bodies[0].spawn, 1);
  EXPECT_EQ(s.pending_spawns(), 1u);
}

// objects.txt keeps ranges, spawn indices, rest offsets (9 significant digits: the float's own
// value back) and every sheet's triangles (read back as one sheet).
TEST(SolverObjects, ObjectsFileRoundTrip) {
  SceneObjects o;
  o.bodies.push_back({4, 2, 3, {vec3{0.1f, -0.2f, 0.3f}, vec3{-0.1f, 0.2f, -0.3f}}, nullptr});
  o.cloths.push_back({0, 3, 0, {int3{0, 1, 2}}});
  o.cloths.push_back({6, 3, 1, {int3{6, 7, 8}}});
  const std::string path = (std::filesystem::temp_directory_path() / "seamless_objects_test.txt").string();
  write_objects(path, o);
  const SceneObjects r = read_objects(path);
  std::filesystem::remove(path);
  ASSERT_EQ(r.bodies.size(), 1u);
  EXPECT_EQ(r.bodies[0].first, 4);
  EXPECT_EQ(r.bodies[0].count, 2);
  EXPECT_EQ(r.bodies[0].spawn, 3);
  EXPECT_EQ(r.bodies[0].rest[1].z, -0.3f);
  ASSERT_EQ(r.cloths.size(), 1u);
  ASSERT_EQ(r.cloths[0].triangles.size(), 2u);
  EXPECT_EQ(r.cloths[0].triangles[1].x, 6);
}

}  // namespace
}  // namespace seamless::test
