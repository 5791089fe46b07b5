// TUM trajectory I/O and ground-truth interpolation (linear translation, slerp rotation).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.hpp"
#include "io/trajectory.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {
TumPose pose(double t, double x, double y, double z, double angle_z) {
  TumPose p;
  p.timestamp = t;
  p.t[0] = x;
  p.t[1] = y;
  p.t[2] = z;
  p.q[2] = std::sin(angle_z / 2);
  p.q[3] = std::cos(angle_z / 2);
  return p;
}
}  // namespace

TEST(Trajectory, WriteReadRoundTrip) {
  TmpDir dir("traj");
  Trajectory tr = {pose(1305031229.528748, 1.25, -0.5, 2.0, 0.3), pose(1305031229.564425, 1.3, -0.4, 2.1, -2.5)};
  write_tum_trajectory(dir / "t.txt", tr);
  Trajectory back = read_tum_trajectory(dir / "t.txt");
  ASSERT_EQ(back.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(back[i].timestamp, tr[i].timestamp, 1e-6);  // microseconds, as TUM writes them
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(back[i].t[k], tr[i].t[k], 1e-7);
    // q and -q are the same rotation; the writer may pick either sign.
    double dot = 0;
    for (int k = 0; k < 4; ++k) dot += back[i].q[k] * tr[i].q[k];
    EXPECT_NEAR(std::fabs(dot), 1.0, 1e-9);
  }
}

TEST(Trajectory, Se3ConversionIsConsistent) {
  TumPose p = pose(0, 1, 2, 3, 1.0);
  SE3 T = p.se3();
  // Rotation by 1 rad about z maps x to (cos 1, sin 1, 0).
  vec3 x = T.rotate({1, 0, 0});
  EXPECT_NEAR(x.x, std::cos(1.0), 1e-6);
  EXPECT_NEAR(x.y, std::sin(1.0), 1e-6);
  TumPose q = TumPose::from_se3(0, T);
  double dot = 0;
  for (int k = 0; k < 4; ++k) dot += q.q[k] * p.q[k];
  EXPECT_NEAR(std::fabs(dot), 1.0, 1e-6);
}

TEST(Trajectory, InterpolationIsLinearAndSlerp) {
  Trajectory tr = {pose(10.0, 0, 0, 0, 0.0), pose(10.04, 0.4, -0.2, 0.1, 1.2)};
  auto p = interpolate_pose(tr, 10.01, 0.1);  // a quarter of the way
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->t[0], 0.1, 1e-12);
  EXPECT_NEAR(p->t[1], -0.05, 1e-12);
  EXPECT_NEAR(p->t[2], 0.025, 1e-12);
  // slerp about one axis: the angle moves linearly, a quarter of 1.2 rad.
  EXPECT_NEAR(2 * std::atan2(p->q[2], p->q[3]), 0.3, 1e-9);
  EXPECT_FALSE(interpolate_pose(tr, 9.99, 0.1));    // before the first sample
  EXPECT_FALSE(interpolate_pose(tr, 10.05, 0.1));   // after the last
  EXPECT_FALSE(interpolate_pose(tr, 10.01, 0.03));  // samples 0.04 s apart: a gap
  EXPECT_TRUE(interpolate_pose(tr, 10.04, 0.03));   // an exact sample needs no interpolation
}

TEST(Trajectory, SlerpTakesTheShortArc) {
  TumPose a = pose(0, 0, 0, 0, 0.1), b = pose(1, 0, 0, 0, -0.1);
  for (double& q : b.q) q = -q;  // same rotation, other sign
  auto p = interpolate_pose({a, b}, 0.5, 2.0);
  ASSERT_TRUE(p);
  EXPECT_NEAR(std::fabs(p->q[3]), 1.0, 1e-12);  // halfway between +0.1 and -0.1 rad is identity
}

TEST(Trajectory, BadFilesNameTheProblem) {
  TmpDir dir("trajbad");
  std::ofstream(dir / "order.txt") << "2 0 0 0 0 0 0 1\n1 0 0 0 0 0 0 1\n";
  std::ofstream(dir / "short.txt") << "# c\n1 0 0 0 0 0 1\n";
  std::ofstream(dir / "quat.txt") << "1 0 0 0 0 0 0 3\n";
  for (auto [file, needle] : {std::pair{"order.txt", "backwards"}, {"short.txt", "line 2"}, {"quat.txt", "norm"}}) {
    try {
      read_tum_trajectory(dir / file);
      ADD_FAILURE() << file;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(file), std::string::npos) << e.what();
    }
  }
}
