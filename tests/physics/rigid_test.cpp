// Rigid bodies by shape matching: a resting cube keeps its shape and comes to rest; Coulomb
// friction on an incline.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.hpp"
#include "physics/builders.hpp"
#include "physics/particle_solver.hpp"
#include "physics_test_util.hpp"

namespace seamless {
namespace {

// Largest distance of a particle from the best rigid transform (Kabsch) of its rest offset.
double rigid_fit_error(const std::vector<vec3>& x, const std::vector<vec3>& q) {
  Eigen::Vector3d cx = Eigen::Vector3d::Zero(), cq = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i) {
    cx += Eigen::Vector3d(x[i].x, x[i].y, x[i].z);
    cq += Eigen::Vector3d(q[i].x, q[i].y, q[i].z);
  }
  cx /= static_cast<double>(x.size()), cq /= static_cast<double>(x.size());
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < x.size(); ++i)
    H += (Eigen::Vector3d(q[i].x, q[i].y, q[i].z) - cq) * (Eigen::Vector3d(x[i].x, x[i].y, x[i].z) - cx).transpose();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  double worst = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    Eigen::Vector3d r = R * (Eigen::Vector3d(q[i].x, q[i].y, q[i].z) - cq) + cx;
    worst = std::max(worst, (r - Eigen::Vector3d(x[i].x, x[i].y, x[i].z)).norm());
  }
  return worst;
}

// A 4x4x4 cube dropped 1 cm onto a smooth floor (half-space SDF). After 3 s every particle must
// be within 1e-3 diameters of a rigid transform of its rest position (shape matching is the last
// projection of each iteration, so only float rounding remains: ~1e-7 m against 4e-5 m) and the
// cube must have stopped (below 1e-3 m/s: pre-stabilisation removes the remaining overlap
// without adding velocity). On a one-particle scene layer the same cube keeps rocking on the
// bumps at ~0.4 cm/s; that figure is printed, not asserted (docs/PHYSICS.md, known limitations).
void resting_cube(bool particle_floor, double& err, float& vmax, float& centre_y) {
  SolverParams p;
  const float d = p.particle_diameter;
  ParticleSolver s(p, Device::CPU);
  if (particle_floor) s.add_static_particles(test::static_layer(0.f, -0.4f, 0.4f, -0.4f, 0.4f, d));
  else s.set_scene_sdf(test::half_space({0.f, 1.f, 0.f}, 0.5f * d));  // surface where particles at y = 0 end
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {4 * d, 4 * d, 4 * d}, c.position = {0.01f, d + 1.5f * d + 0.01f, 0.f};
  ParticleBatch b = make_rigid(c, p);
  s.add_batch(b);
  for (int i = 0; i < 300; ++i) s.step();
  ParticleState st = s.download_state();
  err = rigid_fit_error(st.x, b.rest);
  vmax = 0.f;
  for (const vec3& v : st.v) vmax = std::max(vmax, length(v));
  centre_y = s.rigid_frames()[0].centre.y;
}

TEST(PhysicsRigid, RestingCubeKeepsShapeAndComesToRest) {
  const float d = SolverParams{}.particle_diameter;
  double err;
  float vmax, cy;
  resting_cube(false, err, vmax, cy);
  std::printf("resting cube on a plane: shape error %.3g diameters, max speed %.3g m/s\n", err / d, vmax);
  EXPECT_LE(err, 1e-3 * d);
  EXPECT_LT(vmax, 1e-3f);
  EXPECT_NEAR(cy, d + 1.5f * d, 0.1f * d);  // resting on the plane, not sunk into it
  resting_cube(true, err, vmax, cy);
  std::printf("resting cube on scene particles: shape error %.3g diameters, max speed %.3g m/s\n", err / d, vmax);
  EXPECT_LE(err, 1e-3 * d);
  EXPECT_GT(cy, d);
}

// A 4x4x4 cube of 2 cm particles (configs/real/tum_desk.yaml's) dropped 1 cm onto a rough scan: two
// layers of scene particles (a surface and one beneath, as scene_interior_depth gives) whose
// heights scatter by up to +-3 mm (a Kinect's depth noise at 1-1.5 m). Returns the fastest particle
// after the landing (from 0.2 s to 3 s) and how far the centre moved from where it first settled.
struct RoughRun {
  float vmax_after_landing = 0.f, drift = 0.f;
};
RoughRun cube_on_rough_scan() {
  SolverParams p;
  p.particle_diameter = 0.02f;
  const float d = p.particle_diameter;
  ParticleSolver s(p, Device::CPU);
  std::vector<vec3> scan;
  std::uint32_t h = 12345u;
  auto jitter = [&] {  // a fixed LCG: the same scan on every machine
    h = h * 1664525u + 1013904223u;
    return (static_cast<float>(h >> 8) / 16777216.f * 2.f - 1.f) * 0.003f;
  };
  for (const vec3& q : test::static_layer(0.f, -0.2f, 0.2f, -0.2f, 0.2f, d)) {
    scan.push_back({q.x, q.y + jitter(), q.z});
    scan.push_back({q.x, q.y - d + jitter(), q.z});
  }
  s.add_static_particles(scan);
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {4 * d, 4 * d, 4 * d}, c.position = {0.003f, d + 1.5f * d + 0.013f, -0.002f};
  s.add_batch(make_rigid(c, p));
  RoughRun r;
  vec3 settled{0.f, 0.f, 0.f};
  for (int i = 1; i <= 300; ++i) {
    s.step();
    if (i == 20) settled = s.rigid_frames()[0].centre;
    if (i <= 20) continue;
    for (const vec3& v : s.download_state().v) r.vmax_after_landing = std::max(r.vmax_after_landing, length(v));
    r.drift = std::max(r.drift, length(s.rigid_frames()[0].centre - settled));
  }
  return r;
}

TEST(PhysicsRigid, CubeRestingOnARoughScanIsNotThrown) {
  // A body resting on a few bumps must not be kicked: on the real tum_desk scan a lone cube was
  // thrown off the desk at up to 9.6 m/s when pre-stabilisation still spread a rigid particle's
  // correction over its body (docs/PHYSICS.md). Landing from 1 cm gives 0.44 m/s, gone within the
  // first 0.2 s; after it the cube may rock on the bumps at ~0.4 cm/s (the regular layer's figure
  // above) but must neither reach 0.1 m/s (a tenth of the drop speed's order) nor wander off:
  // less than a quarter particle (5 mm) from where it settled.
  const RoughRun r = cube_on_rough_scan();
  std::printf("cube on a rough scan: fastest particle after landing %.3f m/s, drift %.4f m\n", r.vmax_after_landing,
              r.drift);
  EXPECT_LT(r.vmax_after_landing, 0.1f);
  EXPECT_LT(r.drift, 0.005f);
}

struct InclineRun {
  double travel_1s = 0, travel_2s = 0;  // along the slope, metres
  double max_travel = 0;                // largest |travel| over the 2 s
  double accel = 0;                     // fitted from the motion between 0.2 s and 1 s, m/s^2
};

// A 4x4x4 cube on a smooth 20-degree incline (a half-space SDF), released at rest with its bottom
// particles 1 mm above contact; 2 s.
InclineRun incline(float mu) {
  SolverParams p;
  p.static_friction = mu, p.kinetic_friction = mu;
  const float d = p.particle_diameter, th = 20.f * kernels::kPi / 180.f;
  ParticleSolver s(p, Device::CPU);
  vec3 n{std::sin(th), std::cos(th), 0.f}, down{std::cos(th), -std::sin(th), 0.f};
  s.set_scene_sdf(test::half_space(n, 0.f));
  SpawnParams c;
  c.kind = SpawnKind::rigid, c.size = {4 * d, 4 * d, 4 * d}, c.rotation = {0.f, 0.f, -20.f};
  c.position = n * (2 * d + 0.001f);  // bottom particle centres one radius + 1 mm above the plane
  s.spawn(c);
  const vec3 c0 = s.rigid_frames()[0].centre;
  // Least squares s(t) = s0 + v0 t + a t^2 / 2 over t in [0.2, 1].
  Eigen::MatrixXd A(81, 3);
  Eigen::VectorXd y(81);
  InclineRun r;
  for (int i = 1; i <= 200; ++i) {
    s.step();
    double t = i * p.dt, along = dot(s.rigid_frames()[0].centre - c0, down);
    r.max_travel = std::max(r.max_travel, std::fabs(along));
    if (i == 100) r.travel_1s = along;
    if (i == 200) r.travel_2s = along;
    if (i < 20 || i > 100) continue;
    A.row(i - 20) << 1.0, t, 0.5 * t * t;
    y(i - 20) = along;
  }
  Eigen::Vector3d coef = A.colPivHouseholderQr().solve(y);
  r.accel = coef(2);
  return r;
}

// Coulomb friction (Macklin 2014 section 6.1): tan 20 deg = 0.364 < 0.5 holds the cube still.
// The only travel allowed is the drop onto the slope: the cube falls straight down until its
// 1 mm gap along the normal has closed, which moves its centre 1 mm * tan 20 = 0.364 mm along the
// slope; after that static friction must hold it (per-substep jitter of the resting contact is a
// fraction of the 0.25 mm that gravity predicts per substep: 0.1 mm margin). Between 1 s and 2 s
// it must not drift by more than 0.1 mm, less than the g sin 20 dt_sub^2 = 0.084 mm that one
// substep of sliding would add (it crept 15 mm/s before the body-level static friction of
// kernels::body_static_friction). Below the threshold it must slide: mu = 0.3 and 0.1 give
// g (sin 20 - mu cos 20) = 0.589 and 2.43 m/s^2 (10 % acceptance tolerance).
TEST(PhysicsFriction, CubeOnIncline) {
  const double th = 20.0 * 3.14159265358979 / 180.0, g = 9.81;
  InclineRun stick = incline(0.5f);
  std::printf("incline mu 0.5: travel %.4g m after 1 s, %.4g m after 2 s, largest %.4g m, acceleration %.4g m/s^2\n",
              stick.travel_1s, stick.travel_2s, stick.max_travel, stick.accel);
  EXPECT_LT(stick.max_travel, 1e-3 * std::tan(th) + 1e-4);
  EXPECT_LT(std::fabs(stick.travel_2s - stick.travel_1s), 1e-4);
  EXPECT_LT(std::fabs(stick.accel), 0.02 * g * std::sin(th));
  for (float mu : {0.3f, 0.1f}) {
    InclineRun slide = incline(mu);
    const double expect = g * (std::sin(th) - mu * std::cos(th));
    std::printf("incline mu %.1f: acceleration %.4f m/s^2, expected %.4f\n", mu, slide.accel, expect);
    EXPECT_NEAR(slide.accel, expect, 0.1 * expect);
  }
}

// The OBJ reader of rigid mesh bodies (fuzzing found std::stoi's exception escape and
// face indices past the vertices read out of bounds; tinyobjloader reads the file now). A
// valid file with every kind of face reference gives a solid; each bad file is an InputError
// naming the file and the problem (and the line, where tinyobjloader tells it).
std::string write_obj(const std::string& name, const std::string& text) {
  const std::string path = std::string(SEAMLESS_BUILD_DIR) + "/" + name;
  std::FILE* f = std::fopen(path.c_str(), "w");
  std::fputs(text.c_str(), f);
  std::fclose(f);
  return path;
}

bool same(int3 a, int3 b) { return a.x == b.x && a.y == b.y && a.z == b.z; }

TEST(ObjReader, FaceReferencesOfEveryKindMakeAClosedCube) {
  // A unit cube: quads of 1-based "i", "i/t", "i//n", "i/t/n" and negative (relative) references.
  const std::string cube =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\nvt 0 0\nvn 0 0 1\n"
      "f 1 3 4 2\nf 5/1 6/1 8/1 7/1\nf 1//1 2//1 6//1 5//1\nf -6 -5 -1 -2\nf 1/1/1 5/1/1 7/1/1 3/1/1\nf 2 4 8 6\n";
  // The triangles are fans around each quad's first vertex, 0-based: "f 1 3 4 2" gives (0 2 3)
  // and (0 3 1); "f -6 -5 -1 -2", after 8 vertices, is "f 3 4 8 7": (2 3 7) and (2 7 6);
  // "f 1/1/1 5/1/1 7/1/1 3/1/1" starts with (0 4 6).
  const ObjMesh m = read_obj(write_obj("cube.obj", cube));
  ASSERT_EQ(m.v.size(), 8u);
  ASSERT_EQ(m.f.size(), 12u);
  EXPECT_TRUE(same(m.f[0], {0, 2, 3}));
  EXPECT_TRUE(same(m.f[1], {0, 3, 1}));
  EXPECT_TRUE(same(m.f[6], {2, 3, 7}));
  EXPECT_TRUE(same(m.f[7], {2, 7, 6}));
  EXPECT_TRUE(same(m.f[8], {0, 4, 6}));
  EXPECT_EQ(m.v[7].x, 1.f);
  EXPECT_EQ(m.v[7].y, 1.f);
  EXPECT_EQ(m.v[7].z, 1.f);
  // Fitted into 0.5 m at 0.05 m: the cube spans [-0.25, 0.25] on each axis and the cell centres
  // are multiples of 0.05. Every centre strictly inside (|coordinate| <= 0.2: 9 x 9 x 9) is
  // filled; those on the faces (+-0.25) may or may not be (ray parity on a face): 729 to 1331.
  const std::vector<vec3> cells = voxelize_obj(write_obj("cube.obj", cube), 0.05f, vec3{0.5f, 0.5f, 0.5f});
  for (const vec3& c : cells) {
    EXPECT_LE(std::fabs(c.x), 0.25f + 1e-5f);
    EXPECT_LE(std::fabs(c.y), 0.25f + 1e-5f);
    EXPECT_LE(std::fabs(c.z), 0.25f + 1e-5f);
  }
  EXPECT_GE(cells.size(), 729u);
  EXPECT_LE(cells.size(), 1331u);
}

TEST(ObjReader, BadFilesSayWhatAndWhere) {
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  std::string face300 = "f";  // 300 vertices: tinyobjloader keeps a face's vertex count in a byte
  for (int k = 0; k < 100; ++k) face300 += " 1 2 3";
  // The messages of tinyobjloader (a face vertex 0 or not a number stops it, with the line) and
  // of our checks of what it read (it resolves indices without checking them, so these name the
  // face, counting the file's faces). It takes a vertex coordinate it cannot read as 0 and a face
  // vertex by its leading digits (atoi), so "v 0 0" and "f 1 2 3x" are read, not rejected.
  struct Case {
    std::string text, message;
  } cases[] = {
      {tri + "f 1 2 x\n", "face index. line 4"},
      {tri + "f 1 2 0\n", "face index. line 4"},
      {tri + "f 1 2 4\n", "face 1: face vertex 4 does not exist (the file has 3 vertices)"},
      {tri + "f 1 2 3\nf 3 2 1\nf 1 2 5\n# end\n", "face 3: face vertex 5 does not exist (the file has 3 vertices)"},
      {tri + "f -1 -2 -4\n", "face 1 has a negative vertex number that counts back past the first vertex"},
      {"v 0 0 1e999\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "vertex 1 is not a finite point"},
      {tri, "has no triangles"},
      {tri + face300 + "\n", "a face has 256 vertices or more, more than tinyobjloader can read"},
      {tri + "f 1 2\n", "has no triangles (expected OBJ 'v' and 'f' lines; tinyobjloader: Degenerated face found)"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.text);
    try {
      voxelize_obj(write_obj("bad.obj", c.text), 0.05f, vec3{0.5f, 0.5f, 0.5f});
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("bad.obj"), std::string::npos) << e.what();
    }
  }
  try {
    read_obj(std::string(SEAMLESS_BUILD_DIR) + "/no-such-mesh.obj");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot open mesh file '"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no-such-mesh.obj"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace seamless
