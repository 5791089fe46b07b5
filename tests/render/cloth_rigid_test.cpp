// Cloth is one two-sided mesh lit on whichever side is seen; rigid bodies are boxes in their
// shape-matching frames.
#include <cmath>
#include <memory>

#include "core/phase.hpp"
#include "physics/particle_solver.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

// An n x n sheet in the plane z = 2, side 1 m; `flip` reverses the triangles' winding, so the
// camera sees the other face of the same sheet.
struct Sheet {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  ClothDraw cloth;
  Sheet(int n, bool flip) {
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        x.push_back(vec3{-0.5f + static_cast<float>(i) / (n - 1), -0.5f + static_cast<float>(j) / (n - 1), 2.f});
    ph.assign(x.size(), phase::kCloth);
    for (int j = 0; j + 1 < n; ++j)
      for (int i = 0; i + 1 < n; ++i) {
        const int a = j * n + i, b = a + 1, c = a + n + 1, d = a + n;
        cloth.triangles.push_back(flip ? int3{a, c, b} : int3{a, b, c});
        cloth.triangles.push_back(flip ? int3{a, d, c} : int3{a, c, d});
      }
  }
  DrawList list() const {
    DrawList l;
    l.positions = x, l.phases = ph, l.particle_radius = 0.01f, l.cloths = {cloth};
    return l;
  }
};

// Light travelling along the view direction (from the camera onto the sheet): with the normal
// turned to the visible side, diffuse = n . l = 1 at the centre, so the colour is the full cloth
// colour on either face. Without the turn the back face would get the ambient part only (0.2 of
// it). Tolerance: 8-bit rounding, 2 levels.
TEST(RenderCloth, BothFacesAreLit) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p;
  p.light_dir = {0.f, 0.f, 1.f};
  p.ambient = 0.2f;
  p.cloth_color = {200 / 255.f, 150 / 255.f, 50 / 255.f};
  const Intrinsics K = intrinsics(100.f, 79.5f, 59.5f, 160, 120);
  Renderer r(p, K.width, K.height);
  for (bool flip : {false, true}) {
    Sheet s(9, flip);
    Pixels img(r.render(s.list(), camera(K)));
    const uchar3 c = img.at(80, 60);
    EXPECT_LE(max_diff(c, uchar3{200, 150, 50}), 2)
        << (flip ? "back" : "front") << " face: " << int(c.x) << " " << int(c.y) << " " << int(c.z);
  }
}

// Light from behind the sheet: whichever face is seen, it faces away from the light and shows
// the ambient part only, on both faces alike (one mesh, one rule).
TEST(RenderCloth, LightFromBehindGivesAmbientOnBothFaces) {
  SEAMLESS_REQUIRE_EGL();
  RenderParams p;
  p.light_dir = {0.f, 0.f, -1.f};
  p.ambient = 0.5f;
  p.cloth_color = {200 / 255.f, 150 / 255.f, 50 / 255.f};
  const Intrinsics K = intrinsics(100.f, 79.5f, 59.5f, 160, 120);
  Renderer r(p, K.width, K.height);
  for (bool flip : {false, true}) {
    Pixels img(r.render(Sheet(9, flip).list(), camera(K)));
    EXPECT_LE(max_diff(img.at(80, 60), uchar3{100, 75, 25}), 2) << (flip ? "back" : "front");
  }
}

// The rigid-body scenes: light from the camera, the rigid colour (180, 60, 40), black background.
RenderParams rigid_params() {
  RenderParams p;
  p.light_dir = {0.f, 0.f, 1.f};
  p.rigid_color = {180 / 255.f, 60 / 255.f, 40 / 255.f};
  p.background = {0.f, 0.f, 0.f};
  return p;
}

// A box 0.4 x 0.2 x 0.2 m (half extents 0.2, 0.1, 0.1) at (0, 0, 2), facing the camera: its
// front face z = 1.9 covers [fx x / 1.9 + cx] x [fy y / 1.9 + cy]; a one-pixel margin as for
// the mesh view. The front face's normal points at the camera and the light comes from it, so
// the face has the full rigid colour.
TEST(RenderRigid, BoxCoversItsProjection) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(100.f, 79.5f, 59.5f, 160, 120);
  Renderer r(rigid_params(), K.width, K.height);
  DrawList l;
  l.rigids.push_back(RigidDraw{SE3{mat3::identity(), {0.f, 0.f, 2.f}}, {0.2f, 0.1f, 0.1f}, nullptr});
  Pixels img(r.render(l, camera(K)));
  const float u0 = 100.f * -0.2f / 1.9f + 79.5f, u1 = 100.f * 0.2f / 1.9f + 79.5f;
  const float v0 = 100.f * -0.1f / 1.9f + 59.5f, v1 = 100.f * 0.1f / 1.9f + 59.5f;
  for (int v = 0; v < img.h; ++v)
    for (int u = 0; u < img.w; ++u) {
      if (u > u0 + 1 && u < u1 - 1 && v > v0 + 1 && v < v1 - 1) {
        EXPECT_LE(max_diff(img.at(u, v), uchar3{180, 60, 40}), 2) << u << "," << v;
      }
      if (u < u0 - 1 || u > u1 + 1 || v < v0 - 1 || v > v1 + 1) {
        EXPECT_TRUE(same(img.at(u, v), uchar3{0, 0, 0})) << u << "," << v;
      }
    }
}

// A body with its own mesh: a 0.4 x 0.2 m rectangle in the body frame (normal -z), turned 90
// degrees about z and moved to (dx, 0, 2), covers x in [dx - 0.1, dx + 0.1], y in [-0.2, 0.2] at z = 2:
// pixels [fx x / 2 + cx] x [fy y / 2 + cy] (1 px margin). Drawn twice with two poses: the mesh is
// uploaded once and moved by the frame only.
TEST(RenderRigid, BodyMeshMovesWithItsFrame) {
  SEAMLESS_REQUIRE_EGL();
  const Intrinsics K = intrinsics(100.f, 79.5f, 59.5f, 160, 120);
  Renderer r(rigid_params(), K.width, K.height);
  auto m = std::make_shared<BodyMesh>();
  m->positions = {{-0.2f, -0.1f, 0.f}, {0.2f, -0.1f, 0.f}, {0.2f, 0.1f, 0.f}, {-0.2f, 0.1f, 0.f}};
  m->normals.assign(4, vec3{0.f, 0.f, -1.f});
  m->triangles = {{0, 1, 2}, {0, 2, 3}};
  for (float dx : {0.1f, -0.3f}) {
    DrawList l;
    l.rigids.push_back(RigidDraw{SE3{rotation({0.f, 0.f, 1.f}, 1.5707963f), {dx, 0.f, 2.f}}, {1.f, 1.f, 1.f}, m});
    Pixels img(r.render(l, camera(K)));
    const float u0 = 100.f * (dx - 0.1f) / 2.f + 79.5f, u1 = 100.f * (dx + 0.1f) / 2.f + 79.5f;
    const float v0 = 100.f * -0.2f / 2.f + 59.5f, v1 = 100.f * 0.2f / 2.f + 59.5f;
    int inside = 0;
    for (int v = 0; v < img.h; ++v)
      for (int u = 0; u < img.w; ++u) {
        if (u > u0 + 1 && u < u1 - 1 && v > v0 + 1 && v < v1 - 1) {
          EXPECT_LE(max_diff(img.at(u, v), uchar3{180, 60, 40}), 2) << u << "," << v;
          ++inside;
        }
        if (u < u0 - 1 || u > u1 + 1 || v < v0 - 1 || v > v1 + 1) {
          EXPECT_TRUE(same(img.at(u, v), uchar3{0, 0, 0})) << u << "," << v << " (a box drawn instead?)";
        }
      }
    EXPECT_GT(inside, 100);  // 10 x 20 pixels less the margins
  }
}

// make_draw_list: each body in the frames (found by its first particle id) is posed by its frame,
// with its mesh or the box around its rest offsets plus one radius; cloth triangles of particles
// not in the state (sheets spawned later) are left out. Exact arithmetic on the given numbers: the
// 1e-6 tolerance is float rounding of 0.3 + 0.02.
TEST(RenderRigid, DrawListFromTheSolversObjects) {
  ParticleState st;
  const mat3 R = rotation({0.f, 0.f, 1.f}, 0.5f);
  const vec3 c{1.f, 2.f, 3.f};
  SceneObjects objects;
  RigidBody box{0, 3, 2, {}, nullptr};
  for (vec3 q : {vec3{-0.3f, -0.1f, -0.05f}, vec3{0.3f, 0.1f, 0.05f}, vec3{0.3f, -0.1f, 0.f}}) {
    st.x.push_back(R * q + c);
    st.phase.push_back(phase::kRigid);
    box.rest.push_back(q);
  }
  st.x.push_back({0.f, 0.f, 0.f}), st.phase.push_back(phase::kCloth);
  auto mesh = std::make_shared<BodyMesh>();
  objects.bodies = {{10, 1, 0, {vec3{0.f, 0.f, 0.f}}, mesh}, box};      // the first is not in the frames
  objects.cloths.push_back({0, 0, 1, {int3{0, 1, 3}, int3{0, 1, 4}}});  // id 4: not spawned yet
  RigidFrame f;
  f.centre = c;
  const float s = std::sin(0.25f);
  f.rotation = {0.f, 0.f, s, std::cos(0.25f)};  // 0.5 rad about z
  f.first = 0, f.count = 3;
  const DrawList d = make_draw_list(st, objects, {f}, 0.02f);
  ASSERT_EQ(d.rigids.size(), 1u);
  EXPECT_NEAR(d.rigids[0].half_extents.x, 0.32f, 1e-6f);
  EXPECT_NEAR(d.rigids[0].half_extents.y, 0.12f, 1e-6f);
  EXPECT_NEAR(d.rigids[0].half_extents.z, 0.07f, 1e-6f);
  EXPECT_EQ(d.rigids[0].mesh, nullptr);
  EXPECT_NEAR(length(d.rigids[0].world_T_body.t - c), 0.f, 1e-6f);
  EXPECT_NEAR(d.rigids[0].world_T_body.R.m[0][1], R.m[0][1], 1e-6f);
  EXPECT_EQ(d.positions.size(), 4u);
  ASSERT_EQ(d.cloths.size(), 1u);
  ASSERT_EQ(d.cloths[0].triangles.size(), 1u);
  EXPECT_EQ(d.cloths[0].triangles[0].z, 3);
  // The mesh body, once its frame is there, is drawn with its mesh.
  st.x.resize(11, vec3{0.f, 0.f, 0.f}), st.phase.resize(11, phase::kRigid);
  RigidFrame g{vec3{0.f, 1.f, 0.f}, vec4{0.f, 0.f, 0.f, 1.f}, 10, 1};
  const DrawList e = make_draw_list(st, objects, {f, g}, 0.02f);
  ASSERT_EQ(e.rigids.size(), 2u);
  EXPECT_EQ(e.rigids[1].mesh, mesh);
  EXPECT_EQ(e.cloths[0].triangles.size(), 2u);
}

}  // namespace
}  // namespace seamless::test
