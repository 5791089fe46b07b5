// Test material of dynamic scenes: movers in the synthetic room, against exact geometry. The capsule
// intersection against hand-solved rays; the posed person and ball against their definition; the
// rendered depth and mask against the capsules' distance function; the recording's mask/ and
// movers.txt.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "core/error.hpp"
#include "io/input_params.hpp"
#include "io/movers.hpp"
#include "io/png_io.hpp"
#include "io/record.hpp"
#include "io/synthetic_source.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless {
namespace {

using kernels::movers::Capsule;

TEST(Movers, RayCapsuleHitsTheSideTheEndAndMisses) {
  const Capsule c{{0.f, 0.f, 0.f}, {0.f, 0.f, 1.f}, 0.1f, 1, {1.f, 1.f, 1.f}};
  vec3 n;
  // Across the axis at z = 0.5 from x = -2: the side at x = -0.1, 1.9 m away, normal -x.
  EXPECT_NEAR(kernels::movers::ray_capsule({-2.f, 0.f, 0.5f}, {1.f, 0.f, 0.f}, c, &n), 1.9f, 1e-5f);
  EXPECT_NEAR(n.x, -1.f, 1e-5f);
  // Down the axis from z = 3: the top cap's pole at z = 1.1, 1.9 m away, normal +z.
  EXPECT_NEAR(kernels::movers::ray_capsule({0.f, 0.f, 3.f}, {0.f, 0.f, -1.f}, c, &n), 1.9f, 1e-5f);
  EXPECT_NEAR(n.z, 1.f, 1e-5f);
  // Grazing the bottom cap off-axis: x = 0.06 at z = -2 upwards meets the sphere about a at
  // z = -sqrt(0.1^2 - 0.06^2) = -0.08.
  EXPECT_NEAR(kernels::movers::ray_capsule({0.06f, 0.f, -2.f}, {0.f, 0.f, 1.f}, c, &n), 2.f - 0.08f, 1e-5f);
  // Passing 0.11 m from the axis: no hit.
  EXPECT_LT(kernels::movers::ray_capsule({-2.f, 0.11f, 0.5f}, {1.f, 0.f, 0.f}, c, &n), 0.f);
  // A sphere (a = b) from inside the room's air.
  const Capsule ball{{1.f, 1.f, 1.f}, {1.f, 1.f, 1.f}, 0.25f, 2, {1.f, 1.f, 1.f}};
  EXPECT_NEAR(kernels::movers::ray_capsule({1.f, -1.f, 1.f}, {0.f, 1.f, 0.f}, ball, &n), 1.75f, 1e-5f);
}

std::vector<MoverParams> walker_and_ball() {
  MoverParams person;
  person.path = {{-1.5f, -0.4f, 0.f}, {1.5f, -0.4f, 0.f}};
  person.speed = 1.f;
  person.start = 1.0;
  MoverParams ball;
  ball.kind = MoverKind::ball;
  ball.path = {{0.f, -1.f, 0.f}, {0.f, 1.f, 0.f}};
  ball.speed = 0.5f;
  return {person, ball};
}

TEST(Movers, PosedPersonStandsOnTheFloorAndLeavesAtThePathsEnd) {
  const auto movers = walker_and_ball();
  // t = 0: the person has not started; the ball rests on the floor at its path's start.
  auto s = pose_movers(movers, 0.0);
  ASSERT_EQ(s.count, 1);
  EXPECT_EQ(s.c[0].mover, 2);
  EXPECT_NEAR(s.c[0].a.z - s.c[0].r, 0.f, 1e-6f);
  // t = 1.0: the person stands at the start, legs straight down (sin of phase 0): the feet's
  // spheres touch the floor, the head's top is at 0.93 H + its radius 0.065 H.
  s = pose_movers(movers, 1.0);
  ASSERT_EQ(s.count, 7);  // 6 capsules of the person, then the ball
  float lowest = 1e9f, highest = -1e9f;
  for (int i = 0; i < 6; ++i) {
    EXPECT_EQ(s.c[i].mover, 1);
    for (vec3 e : {s.c[i].a, s.c[i].b})
      lowest = std::min(lowest, e.z - s.c[i].r), highest = std::max(highest, e.z + s.c[i].r);
  }
  EXPECT_NEAR(lowest, 0.f, 1e-5f);
  EXPECT_NEAR(highest, 0.93f * 1.75f + 0.065f * 1.75f, 1e-5f);
  // The ball has rolled 0.5 m along +y.
  EXPECT_NEAR(s.c[6].a.y, -0.5f, 1e-5f);
  // t = 2.5: the person is 1.5 m along the path, at x = 0 (its torso's axis passes there).
  s = pose_movers(movers, 2.5);
  EXPECT_NEAR(s.c[0].a.x, 0.f, 1e-5f);
  // t = 4.1: past the path's end (3 m at 1 m/s from t = 1): the person is gone; so is the ball at t = 4.1.
  EXPECT_EQ(pose_movers(movers, 4.1).count, 0);
}

TEST(Movers, BadPathIsAConfigError) {
  MoverParams m;
  m.path = {{1.f, 1.f, 0.f}};
  EXPECT_THROW(pose_movers({m}, 0.0), ConfigError);
}

// Noise off: every pixel's depth is the exact first hit, so a pixel the mask gives to a mover lies
// on a capsule (distance 0 up to float rounding of the ray, 1e-4 m at 3 m), and every other pixel
// with depth lies on the room and outside every capsule.
TEST(Movers, RenderedMaskAndDepthAgreeWithTheCapsules) {
  InputParams in;
  in.source = InputSource::synthetic;
  in.synthetic.noise = false;
  in.synthetic.trajectory = CameraPath::still;
  in.synthetic.frames = 1;
  // The still camera stands at (0, -1, 1.35) looking at the desk (0, 0.6, 0.75): the person 0.45 m
  // in front of it, the ball on the floor left of the desk, both in view.
  in.synthetic.movers = walker_and_ball();
  in.synthetic.movers[0].start = 0.0;
  in.synthetic.movers[0].path = {{0.f, -0.55f, 0.f}, {1.5f, -0.55f, 0.f}};
  in.synthetic.movers[1].path = {{-1.1f, 1.3f, 0.f}, {-1.1f, 2.f, 0.f}};
  in.synthetic.movers[1].radius = 0.2f;
  SyntheticSource src(in, Device::CPU);
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  ASSERT_EQ(f.mover_mask.width(), f.depth.width());
  ASSERT_TRUE(f.movers.has_value());
  const auto& s = *f.movers;
  const Intrinsics K = f.intrinsics;
  const SE3 T = *f.ground_truth;
  const auto depth = f.depth.cview();
  const auto mask = f.mover_mask.cview();
  int masked = 0, by_id[3] = {0, 0, 0};
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      const float z = depth(x, y);
      const int id = mask(x, y);
      ASSERT_LE(id, 2);
      if (z <= 0.f) continue;
      const vec3 p = T * K.unproject(float(x), float(y), z);
      if (id > 0) {
        ++masked, ++by_id[id];
        ASSERT_NEAR(kernels::movers::distance(s, p), 0.f, 1e-3f) << x << "," << y;
      } else {
        ASSERT_GT(kernels::movers::distance(s, p), -1e-3f) << x << "," << y;
        ASSERT_NEAR(kernels::room::room_sdf(p), 0.f, 1e-3f) << x << "," << y;
      }
    }
  EXPECT_GT(by_id[1], 1000);    // the person fills a good part of the view
  EXPECT_GT(masked, by_id[1]);  // and the ball is seen too
}

TEST(Movers, RecordingWritesMasksAndCapsules) {
  InputParams in;
  in.source = InputSource::synthetic;
  in.synthetic.frames = 3;
  in.synthetic.movers = walker_and_ball();
  SyntheticSource src(in, Device::CPU);
  const auto dir = std::filesystem::temp_directory_path() / "seamless_movers_record";
  std::filesystem::remove_all(dir);
  ASSERT_EQ(record(src, dir.string(), {}), 3);
  int masks = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir / "mask")) {
    ++masks;
    EXPECT_EQ(read_png_u8(e.path().string()).width(), src.intrinsics().width);
  }
  EXPECT_EQ(masks, 3);
  // Frames at t = 0, 1/30, 2/30: only the ball is out (the person starts at t = 1): 1 line each.
  std::ifstream list(dir / "movers.txt");
  std::string line;
  int lines = 0;
  while (std::getline(list, line))
    if (!line.empty() && line[0] != '#') ++lines;
  EXPECT_EQ(lines, 3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace seamless
