// Marching cubes over the voxel blocks against the analytic scene, mesh topology across block
// seams, and the PLY round trip.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "core/error.hpp"

#include "io/ply.hpp"
#include "recon/marching_cubes.hpp"
#include "recon/voxel_hash_volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

using test::Scene;

Mesh fused_mesh(const Scene& s, Device d = Device::CPU, VolumeParams params = test::small_volume_params()) {
  VoxelHashVolume vol(params, d);
  Intrinsics K = test::camera(320, 240, 280.f);
  for (SE3 T : {test::pose({0.f, 0.f, 0.f}), test::pose({0.04f, 0.f, 0.f}), test::pose({-0.04f, 0.02f, 0.f}),
                test::pose({0.f, -0.03f, 0.05f})}) {
    std::vector<vec3> n;
    auto depth = s.render(K, T, &n);
    std::vector<uchar3> c(n.size());
    for (std::size_t i = 0; i < c.size(); ++i) c[i] = test::colour_of(n[i]);
    vol.integrate(Image<float>::from_host(depth, K.width, K.height, Device::CPU),
                  Image<uchar3>::from_host(c, K.width, K.height, Device::CPU), K, T);
  }
  return vol.extract_mesh();
}

vec3 analytic_normal(const Scene& s, vec3 p) {
  const float h = 1e-3f;
  return normalize(vec3{s.sdf(p + vec3{h, 0, 0}) - s.sdf(p - vec3{h, 0, 0}),
                        s.sdf(p + vec3{0, h, 0}) - s.sdf(p - vec3{0, h, 0}),
                        s.sdf(p + vec3{0, 0, h}) - s.sdf(p - vec3{0, 0, h})});
}

TEST(TsdfMesh, VerticesLieOnTheAnalyticSurface) {
  Scene s;
  Mesh m = fused_mesh(s);
  ASSERT_GT(m.triangles.size(), 10000u);
  // Bound (as for the raycast): nearest-pixel depth error (z/f) tan(theta) = 1.6/280 * tan(45 deg)
  // = 5.7 mm for surfaces seen within 45 degrees of head-on; the linear zero crossing along a
  // voxel edge of the sphere's distance adds h^2/(8R) = 0.06 mm.
  const float tol = 1.6f / 280.f + 0.0003f;
  int evaluated = 0;
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    vec3 p = m.positions[i], n = analytic_normal(s, p);
    if (-dot(n, normalize(p)) < std::cos(0.785f)) continue;  // seen obliquely from the cameras
    ++evaluated;
    EXPECT_LE(std::fabs(s.sdf(p)), tol) << "vertex " << p.x << " " << p.y << " " << p.z;
    // Normals from the TSDF gradient: within ~0.1 rad (see the raycast test).
    EXPECT_GT(dot(m.normals[i], n), 0.995f)
        << p.x << " " << p.y << " " << p.z << " n " << m.normals[i].x << " " << m.normals[i].y << " " << m.normals[i].z
        << " true " << n.x << " " << n.y << " " << n.z;
  }
  EXPECT_GT(evaluated, int(m.positions.size() * 8 / 10));
  // Colour fused from the normal encoding: a wall vertex is (127, 127, 0).
  for (std::size_t i = 0; i < m.positions.size(); ++i)
    if (std::fabs(m.positions[i].x) > 0.5f && std::fabs(m.positions[i].y) < 0.3f) {
      EXPECT_NEAR(m.colors[i].x, 127, 2);
      EXPECT_NEAR(m.colors[i].z, 0, 2);
      break;
    }
}

// Every edge is shared by at most two triangles that run along it in opposite directions
// (consistently oriented 2-manifold), triangles face outwards, and no edge is open inside the
// well-observed wall: no cracks at the seams between blocks.
TEST(TsdfMesh, ManifoldOrientedAndSeamless) {
  Scene s;
  Mesh m = fused_mesh(s);
  std::map<std::pair<int, int>, int> directed;
  for (const int3& t : m.triangles) {
    int v[3] = {t.x, t.y, t.z};
    for (int k = 0; k < 3; ++k) {
      int uses = ++directed[std::make_pair(v[k], v[(k + 1) % 3])];
      ASSERT_EQ(uses, 1) << "edge used twice the same way";
    }
    vec3 a = m.positions[t.x], b = m.positions[t.y], c = m.positions[t.z];
    vec3 fn = cross(b - a, c - a);
    if (length(fn) > 1e-9f) {
      EXPECT_GT(dot(fn, analytic_normal(s, (a + b + c) / 3.f)), 0.f) << "inward triangle";
    }
  }
  int open_inside = 0;
  for (const auto& [e, n] : directed) {
    if (directed.count({e.second, e.first})) continue;  // shared by two triangles
    vec3 a = m.positions[e.first], b = m.positions[e.second];
    auto interior = [&](vec3 p) {
      return std::fabs(p.x) < 0.6f && std::fabs(p.y) < 0.4f && std::fabs(p.x - s.center.x) > 0.35f;
    };
    if (interior(a) && interior(b)) ++open_inside;
  }
  EXPECT_EQ(open_inside, 0);
}

// The mesh is the same, vertex for vertex, whatever hash slots its blocks landed in: another table
// size puts every block in another slot (and another order of the live slots), and the mesh's
// blocks are taken in coordinate order.
TEST(TsdfMesh, VertexOrderDoesNotDependOnTheHashSlots) {
  Scene s;
  VolumeParams wide = test::small_volume_params();
  wide.hash_buckets *= 4;
  const Mesh a = fused_mesh(s), b = fused_mesh(s, Device::CPU, wide);
  ASSERT_GT(a.positions.size(), 1000u);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  auto same = [](vec3 p, vec3 q) { return p.x == q.x && p.y == q.y && p.z == q.z; };
  int moved = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i)
    moved += !same(a.positions[i], b.positions[i]) || !same(a.normals[i], b.normals[i]);
  EXPECT_EQ(moved, 0);
  for (std::size_t i = 0; i < a.triangles.size(); ++i) ASSERT_TRUE(a.triangles[i] == b.triangles[i]) << i;
}

TEST(TsdfMesh, TableIsComplementSymmetric) {
  // Flipping every corner's sign must give the same edges (the surface does not depend on which
  // side we call inside), except for the ambiguous faces, where our rule separates the inside
  // corners: then the edge sets still agree, only the connection differs.
  const auto& t = marching_cubes_table();
  for (int cube = 1; cube < 255; ++cube) {
    std::set<int> a, b;
    for (int k = 0; k < kernels::kMcRow && t[cube * 16 + k] >= 0; ++k) a.insert(t[cube * 16 + k]);
    for (int k = 0; k < kernels::kMcRow && t[(255 - cube) * 16 + k] >= 0; ++k) b.insert(t[(255 - cube) * 16 + k]);
    EXPECT_EQ(a, b) << "cube " << cube;
    // Exactly the edges whose corners differ in sign appear.
    for (int e = 0; e < 12; ++e) {
      int axis = e / 4, j = e % 4, lo = 0, m = 0;
      for (int bit = 0; bit < 3; ++bit) {
        if (bit == axis) continue;
        if (j & (1 << m)) lo |= 1 << bit;
        ++m;
      }
      bool crosses = ((cube >> lo) & 1) != ((cube >> (lo | (1 << axis))) & 1);
      EXPECT_EQ(a.count(e) == 1, crosses) << "cube " << cube << " edge " << e;
    }
  }
}

TEST(TsdfMesh, PlyRoundTrip) {
  Scene s;
  s.sphere = false;
  s.box = true;
  Mesh m = fused_mesh(s);
  ASSERT_GT(m.triangles.size(), 100u);
  std::string path = std::string(SEAMLESS_BUILD_DIR) + "/tsdf_mesh_test.ply";
  write_mesh_ply(path, m);
  Mesh r = read_mesh_ply(path);
  std::remove(path.c_str());
  ASSERT_EQ(r.positions.size(), m.positions.size());
  ASSERT_EQ(r.triangles.size(), m.triangles.size());
  for (std::size_t i = 0; i < m.positions.size(); ++i) {
    EXPECT_EQ(r.positions[i].x, m.positions[i].x);
    EXPECT_EQ(r.normals[i].z, m.normals[i].z);
    EXPECT_EQ(r.colors[i].y, m.colors[i].y);
  }
  for (std::size_t i = 0; i < m.triangles.size(); ++i) EXPECT_TRUE(r.triangles[i] == m.triangles[i]);
  EXPECT_THROW(read_mesh_ply(path), Error);
}

TEST(TsdfMeshParity, CpuAndCudaMeshesAgree) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  Scene s;
  Mesh a = fused_mesh(s, Device::CPU), b = fused_mesh(s, Device::CUDA);
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  ASSERT_EQ(a.positions.size(), b.positions.size());
  // The blocks are meshed in coordinate order on both backends, so the two meshes list the same
  // vertices in the same order and the same triangles: each CUDA vertex within 1e-5 m of the CPU's
  // (both interpolate the same TSDF values; float rounding is ~1e-7 m).
  int far = 0;
  for (std::size_t i = 0; i < a.positions.size(); ++i) far += length(a.positions[i] - b.positions[i]) > 1e-5f;
  EXPECT_EQ(far, 0);
  for (std::size_t i = 0; i < a.triangles.size(); ++i) ASSERT_TRUE(a.triangles[i] == b.triangles[i]) << i;
}

}  // namespace
}  // namespace seamless
