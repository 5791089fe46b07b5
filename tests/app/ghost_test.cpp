// The ghost measure of dynamic scenes (src/app/ghost.cpp, summary.json dynamic.ghost_vertices) against mesh
// vertices placed by hand in and around a person's exact capsules (kernels/scene/movers.hpp).
#include <gtest/gtest.h>

#include "app/ghost.hpp"
#include "io/movers.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless {
namespace {

InputParams person_walking() {
  InputParams in;
  in.source = InputSource::synthetic;
  MoverParams person;
  person.kind = MoverKind::person, person.path = {{-1.f, 1.2f, 0.f}, {1.f, 1.2f, 0.f}}, person.speed = 1.f;
  in.synthetic.movers = {person};
  return in;
}

// 30 poses at 30 Hz: the ground truth (room_T_camera), and the estimate in a world frame that is
// the room turned and moved by world_T_room (as a tracked run's first-camera world would be).
Trajectory poses(const SE3& world_T_room) {
  Trajectory t;
  for (int k = 0; k < 30; ++k) {
    SE3 room_T_camera = SE3::identity();
    room_T_camera.t = {0.1f * k, -1.f, 1.2f};
    t.push_back(TumPose::from_se3(k / 30.0, world_T_room * room_T_camera));
  }
  return t;
}

TEST(Ghost, CountsVerticesInsideTheMoversButNotTheRoomsOwnSurfaces) {
  const InputParams in = person_walking();
  SE3 world_T_room = SE3::identity();
  world_T_room.R = {{{0.f, -1.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, 0.f, 1.f}}};  // 90 degrees about z
  world_T_room.t = {0.3f, -0.2f, 0.1f};
  const Trajectory gt = poses(SE3::identity()), est = poses(world_T_room);
  // Inside the torso at t = 0.5 s (its axis runs up through the walking point, about 1 m up), the
  // room's floor under the person (within the margin of the room's surface: the room), empty
  // space next to the path (nothing), and a point inside the person only at 5 s (after the last
  // ground-truth time: not in the swept volume).
  const kernels::movers::Scene at_half = pose_movers(in.synthetic.movers, 0.5);
  ASSERT_GT(at_half.count, 0);
  vec3 torso = (at_half.c[0].a + at_half.c[0].b) * 0.5f;
  ASSERT_LT(kernels::movers::distance(at_half, torso), -0.05f);
  const vec3 floor{torso.x, torso.y, 0.f};
  ASSERT_LT(std::fabs(kernels::room::room_sdf(floor)), 0.02f);
  const vec3 beside{torso.x, torso.y + 0.8f, torso.z};
  const kernels::movers::Scene late = pose_movers(in.synthetic.movers, 1.8);
  ASSERT_GT(late.count, 0);
  const vec3 later = (late.c[0].a + late.c[0].b) * 0.5f;
  Mesh m;
  for (vec3 q : {torso, floor, beside, later}) m.positions.push_back(world_T_room * q);
  const auto g = ghost_vertices(m, in, est, gt, 0.02f);
  ASSERT_TRUE(g.has_value());
  EXPECT_EQ(g->total, 1);
  EXPECT_EQ(g->by_mover, std::vector<std::int64_t>{1});
  // A second mover, a ball rolling 2 m from the person's path: a vertex inside it at 0.5 s counts
  // for the ball (mover 2), the torso's still for the person.
  InputParams two = in;
  MoverParams ball;
  ball.kind = MoverKind::ball, ball.path = {{-1.f, 3.2f, 0.f}, {1.f, 3.2f, 0.f}}, ball.speed = 0.5f, ball.radius = 0.2f;
  two.synthetic.movers.push_back(ball);
  const kernels::movers::Scene both = pose_movers(two.synthetic.movers, 0.5);
  int ball_capsule = -1;
  for (int i = 0; i < both.count; ++i)
    if (both.c[i].mover == 2) ball_capsule = i;
  ASSERT_GE(ball_capsule, 0);
  Mesh m2 = m;
  m2.positions.push_back(world_T_room * ((both.c[ball_capsule].a + both.c[ball_capsule].b) * 0.5f));
  const auto g2 = ghost_vertices(m2, two, est, gt, 0.02f);
  ASSERT_TRUE(g2.has_value());
  EXPECT_EQ(g2->total, 2);
  EXPECT_EQ(g2->by_mover, (std::vector<std::int64_t>{1, 1}));
  // Without movers, or with no common timestamp, there is no measure.
  InputParams none = in;
  none.synthetic.movers.clear();
  EXPECT_FALSE(ghost_vertices(m, none, est, gt, 0.02f).has_value());
  Trajectory shifted = est;
  for (TumPose& p : shifted) p.timestamp += 100.0;
  EXPECT_FALSE(ghost_vertices(m, in, shifted, gt, 0.02f).has_value());
}

// The seen-through ghost (app/ghost.hpp) against a wall 3 m in front of two cameras: a vertex on
// the wall is seen at, one 1 m in front of it is seen through by both views, one behind the wall or
// out of view is not, and a vertex in front of a hole (no readings) is no evidence.
TEST(Ghost, SeenThroughCountsWhatTheViewsSawThrough) {
  const Intrinsics K;  // 525 / 319.5 / 239.5, 640x480
  Image<float> wall(640, 480, Device::CPU);
  std::vector<float> d(640 * 480, 3.f);
  for (int y = 200; y < 280; ++y)
    for (int x = 400; x < 480; ++x) d[static_cast<std::size_t>(y) * 640 + x] = 0.f;  // a hole: no readings
  wall.buffer().copy_from_host(d.data(), static_cast<std::int64_t>(d.size()));
  SeenViews views;
  SE3 a = SE3::identity(), b = SE3::identity();
  b.t = {0.01f, 0.f, 0.f};  // 1 cm to the side: the same wall at 3 m to within a pixel
  views.add(wall, K, a);
  views.add(wall, K, b);
  ASSERT_EQ(views.size(), 2u);
  Mesh m;
  m.positions = {{0.f, 0.f, 3.f},    // on the wall: seen at
                 {0.f, 0.f, 2.f},    // a metre in front of it, in the middle of the view: seen through
                 {0.f, 0.f, 2.97f},  // 3 cm in front: within the noise and slack margin
                 {0.f, 0.f, 3.5f},   // behind the wall: hidden
                 {0.f, 0.f, -1.f},   // behind the camera
                 {10.f, 0.f, 2.f},   // out of view
                 {0.3f, 0.f, 2.f}};  // projects to x = 398: its 3x3 neighbours reach into the hole
  // The margin at 2 m: 3 sigma = 3 * 1.5e-3 * 4 = 1.8 cm, plus the slack.
  EXPECT_NEAR(seen_through_margin(2.f, 0.05f), 0.068f, 1e-6f);
  const SeenThroughGhost g = seen_through_vertices(m, views, 0.05f);
  EXPECT_EQ(g.mesh_vertices, 7);
  EXPECT_EQ(g.views, 2);
  EXPECT_EQ(g.vertices, 1);
  EXPECT_NEAR(g.fraction(), 1.0 / 7.0, 1e-12);
  // min_views 3: two views cannot count a vertex.
  EXPECT_EQ(seen_through_vertices(m, views, 0.05f, 3).vertices, 0);
  // max_views 1: the first view alone, then min_views 1 finds the vertex.
  EXPECT_EQ(seen_through_vertices(m, views, 0.05f, 1, 1).vertices, 1);
}

}  // namespace
}  // namespace seamless
