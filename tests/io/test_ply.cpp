// io/ply: the one PLY reader and writer. Meshes and particle states round trip bit for bit; the
// same mesh written by hand as ascii (as Open3D and MeshLab re-save it), binary little-endian and
// binary big-endian reads to the same values; files it did not write (other types, element
// orders, extra elements) read right, and bad ones are InputErrors that say what is wrong.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>

#include "core/error.hpp"
#include "core/phase.hpp"
#include "io/ply.hpp"

namespace seamless {
namespace {

std::string write_file(const std::string& name, const std::string& bytes) {
  const std::string path = std::string(SEAMLESS_BUILD_DIR) + "/test_ply_" + name;
  std::FILE* f = std::fopen(path.c_str(), "wb");
  std::fwrite(bytes.data(), 1, bytes.size(), f);
  std::fclose(f);
  return path;
}
std::string binary_ply(const std::string& name, const std::string& header, const std::string& data) {
  return write_file(name, "ply\nformat binary_little_endian 1.0\n" + header + "end_header\n" + data);
}
// The bytes of v in little-endian and in big-endian order (this machine is little-endian: x86-64).
template <class T> std::string le(T v) { return std::string(reinterpret_cast<const char*>(&v), sizeof v); }
template <class T> std::string be(T v) {
  std::string s = le(v);
  std::reverse(s.begin(), s.end());
  return s;
}
std::string face(int a, int b, int c) { return std::string(1, '\3') + le(a) + le(b) + le(c); }

// A triangle with a normal and a colour per vertex; values exact in float and in 6 decimals.
Mesh small_mesh() {
  Mesh m;
  m.positions = {{0.5f, -1.25f, 2.f}, {1.f, 0.f, 0.75f}, {-0.125f, 3.5f, 0.f}, {0.f, 0.f, -8.f}};
  m.normals = {{0.f, 0.f, 1.f}, {0.f, 1.f, 0.f}, {1.f, 0.f, 0.f}, {0.f, -1.f, 0.f}};
  m.colors = {{255, 0, 0}, {0, 255, 0}, {0, 0, 255}, {12, 34, 56}};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

void expect_same_mesh(const Mesh& a, const Mesh& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  ASSERT_EQ(a.normals.size(), b.normals.size());
  ASSERT_EQ(a.colors.size(), b.colors.size());
  ASSERT_EQ(a.triangles.size(), b.triangles.size());
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    EXPECT_EQ(std::memcmp(&a.positions[i], &b.positions[i], sizeof(vec3)), 0) << "vertex " << i;
    if (!a.normals.empty()) {
      EXPECT_EQ(std::memcmp(&a.normals[i], &b.normals[i], sizeof(vec3)), 0) << "normal " << i;
    }
    if (!a.colors.empty()) {
      EXPECT_EQ(std::memcmp(&a.colors[i], &b.colors[i], sizeof(uchar3)), 0) << "colour " << i;
    }
  }
  for (std::size_t i = 0; i < a.triangles.size(); ++i) EXPECT_TRUE(a.triangles[i] == b.triangles[i]) << "face " << i;
}

TEST(Ply, MeshRoundTripsBitForBit) {
  const Mesh m = small_mesh();
  const std::string path = std::string(SEAMLESS_BUILD_DIR) + "/test_ply_roundtrip.ply";
  write_mesh_ply(path, m);
  expect_same_mesh(read_mesh_ply(path), m);
  Mesh bare;  // positions only, and no vertices at all
  bare.positions = m.positions, bare.triangles = m.triangles;
  write_mesh_ply(path, bare);
  expect_same_mesh(read_mesh_ply(path), bare);
  write_mesh_ply(path, Mesh{});
  expect_same_mesh(read_mesh_ply(path), Mesh{});
  std::remove(path.c_str());
}

TEST(Ply, ParticlesRoundTripBitForBitWithEveryPhaseBit) {
  ParticleState s;
  s.x = {{0.1f, 0.2f, 0.3f}, {-1e-7f, 5e4f, 1.f / 3.f}, {0.f, -0.f, 7.f}};
  s.v = {{1.f, 2.f, 3.f}, {0.f, 0.f, -9.81f}, {1e-30f, 0.f, 0.f}};
  s.phase = {phase::kFluid, phase::kRigid | 0x00ABCDEFu, phase::kCloth | phase::kSelfCollide | phase::kStatic | 7u};
  s.inv_mass = {1.f, 1.f, 1.f};
  const std::string path = std::string(SEAMLESS_BUILD_DIR) + "/test_ply_particles.ply";
  write_particles_ply(path, s);
  const ParticleState r = read_particles_ply(path);
  ASSERT_EQ(r.x.size(), 3u);
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(std::memcmp(&r.x[i], &s.x[i], sizeof(vec3)), 0) << i;
    EXPECT_EQ(std::memcmp(&r.v[i], &s.v[i], sizeof(vec3)), 0) << i;
    EXPECT_EQ(r.phase[i], s.phase[i]) << i;
    EXPECT_EQ(r.inv_mass[i], 1.f);
  }
  write_particles_ply(path, ParticleState{});
  EXPECT_EQ(read_particles_ply(path).x.size(), 0u);
  std::remove(path.c_str());
}

// small_mesh() as Open3D's ascii re-save writes it (double coordinates and normals, uint indices),
// and the same table in big-endian binary: both read to small_mesh() exactly.
TEST(Ply, AsciiAndBigEndianReadToTheSameMesh) {
  const std::string ascii =
      "ply\r\nformat ascii 1.0\r\ncomment Created by Open3D\r\nelement vertex 4\r\nproperty double x\r\n"
      "property double y\r\nproperty double z\r\nproperty double nx\r\nproperty double ny\r\nproperty double nz\r\n"
      "property uchar red\r\nproperty uchar green\r\nproperty uchar blue\r\nelement face 2\r\n"
      "property list uchar uint vertex_indices\r\nend_header\r\n"
      "0.5 -1.25 2 0 0 1 255 0 0\r\n1 0 0.75 0 1 0 0 255 0\r\n-0.125 3.5 0 1 0 0 0 0 255\r\n"
      "0 0 -8 0 -1 0 12 34 56\r\n3 0 1 2\r\n3 0 2 3\r\n";
  expect_same_mesh(read_mesh_ply(write_file("ascii.ply", ascii)), small_mesh());

  const Mesh m = small_mesh();
  std::string big =
      "ply\nformat binary_big_endian 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\nproperty uchar green\n"
      "property uchar blue\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n";
  for (std::size_t i = 0; i < 4; ++i) {
    for (float v : {m.positions[i].x, m.positions[i].y, m.positions[i].z}) big += be(v);
    for (float v : {m.normals[i].x, m.normals[i].y, m.normals[i].z}) big += be(v);
    big += std::string{char(m.colors[i].x), char(m.colors[i].y), char(m.colors[i].z)};
  }
  for (const int3& t : m.triangles) big += std::string(1, '\3') + be(t.x) + be(t.y) + be(t.z);
  expect_same_mesh(read_mesh_ply(write_file("big.ply", big)), m);
}

TEST(Ply, ParticlesReadFromAsciiAndBigEndian) {
  const std::uint32_t ph = phase::kRigid | 42u;  // 33554474: beyond a float's exact integers
  const std::string header =
      "element vertex 1\nproperty float x\nproperty float y\nproperty float z\nproperty float vx\n"
      "property float vy\nproperty float vz\nproperty uint phase\nend_header\n";
  const ParticleState a = read_particles_ply(
      write_file("particles_ascii.ply", "ply\nformat ascii 1.0\n" + header + "0.25 -2 3 0 0 -1.5 33554474\n"));
  std::string data;
  for (float v : {0.25f, -2.f, 3.f, 0.f, 0.f, -1.5f}) data += be(v);
  const ParticleState b = read_particles_ply(
      write_file("particles_big.ply", "ply\nformat binary_big_endian 1.0\n" + header + data + be(ph)));
  for (const ParticleState* s : {&a, &b}) {
    ASSERT_EQ(s->x.size(), 1u);
    EXPECT_EQ(s->x[0].x, 0.25f);
    EXPECT_EQ(s->x[0].y, -2.f);
    EXPECT_EQ(s->x[0].z, 3.f);
    EXPECT_EQ(s->v[0].z, -1.5f);
    EXPECT_EQ(s->phase[0], ph);
  }
}

TEST(Ply, ReadsEveryScalarType) {
  const std::string header =
      "element vertex 3\nproperty double x\nproperty short y\nproperty int z\nproperty ushort ny\n"
      "element face 1\nproperty list uchar int vertex_indices\n";
  std::string data;
  for (int i = 0; i < 3; ++i)
    data += le(1.5 + i) + le<std::int16_t>(-2 - i) + le<std::int32_t>(70000 + i) + le<std::uint16_t>(1);
  const Mesh m = read_mesh_ply(binary_ply("types.ply", header, data + face(0, 1, 2)));
  ASSERT_EQ(m.positions.size(), 3u);
  EXPECT_EQ(m.positions[2].x, 3.5f);
  EXPECT_EQ(m.positions[2].y, -4.f);
  EXPECT_EQ(m.positions[2].z, 70002.f);
  ASSERT_EQ(m.normals.size(), 3u);  // ny alone: a normal attribute, nx and nz 0
  EXPECT_EQ(m.normals[1].y, 1.f);
  EXPECT_EQ(m.normals[1].x, 0.f);
}

// Faces before vertices, a property of the faces and an element the mesh does not use: read by
// their header, not by position.
TEST(Ply, ReadsElementsInAnyOrderAndSkipsWhatAMeshDoesNotUse) {
  const std::string header =
      "element face 1\nproperty list uchar int vertex_indices\nproperty uchar flags\n"
      "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
      "element vertex 3\nproperty float x\nproperty float y\nproperty float z\nproperty float quality\n";
  std::string data = face(2, 1, 0) + '\7' + le(0) + le(1);
  for (int i = 0; i < 3; ++i) data += le(float(i)) + le(float(10 + i)) + le(float(20 + i)) + le(0.5f);
  const Mesh m = read_mesh_ply(binary_ply("order.ply", header, data));
  ASSERT_EQ(m.positions.size(), 3u);
  ASSERT_EQ(m.triangles.size(), 1u);
  EXPECT_TRUE(m.triangles[0] == (int3{2, 1, 0}));
  EXPECT_EQ(m.positions[1].y, 11.f);
  EXPECT_EQ(m.positions[2].z, 22.f);
}

TEST(Ply, BadFilesSayWhat) {
  const std::string xyz = "element vertex 3\nproperty float x\nproperty float y\nproperty float z\n";
  const std::string faces = "element face 1\nproperty list uchar int vertex_indices\n";
  std::string verts;
  for (int i = 0; i < 9; ++i) verts += le(static_cast<float>(i));
  struct Case {
    std::string file, message;
  } cases[] = {
      {binary_ply("bad1.ply", xyz + faces, verts + face(0, 1, 3)),
       "face 0 refers to vertex 3, but there are 3 vertices"},
      {binary_ply("bad2.ply", xyz + faces, verts + face(0, -1, 2)), "face 0 refers to vertex -1"},
      {binary_ply("bad3.ply",
                  "element vertex 4000000000000\nproperty float x\nproperty float y\nproperty float z\n" + faces,
                  verts + face(0, 1, 2)),
       "announces 4000000000000 vertices and 1 faces, more than the file's"},
      {binary_ply("bad4.ply", "element vertex 9000000000\n" + faces, face(0, 1, 2)), "the vertices have no property x"},
      {binary_ply("bad5.ply", xyz + faces, verts + std::string(1, '\4') + le(0) + le(1) + le(2) + le(0)),
       "face 0 is not a triangle"},
      {binary_ply("bad6.ply", xyz + faces, verts + std::string(1, '\3') + le(0) + le(1)),
       "element face row 0 is cut short"},
      {binary_ply("bad7.ply", xyz + "property int8 flags\n", verts),
       "announces 3 vertices, more than the file's 36 bytes"},
      {binary_ply("bad8.ply", "element vertex 1\nproperty half x\n", "ab"), "unsupported property type 'half'"},
      {write_file("bad9.ply", "ply\nformat binary_middle_endian 1.0\nend_header\n"),
       "format 'binary_middle_endian' is not one of ascii"},
      {write_file("bad10.ply", "ply\nformat ascii 1.0\n" + xyz + "end_header\n0 0 0\n1 x 0\n2 2 2\n"),
       "element vertex row 1: 'x' is not a number (float)"},
      {write_file("bad11.ply", "ply\nformat ascii 1.0\nelement vertex 1\nproperty uchar red\nend_header\n256\n"),
       "element vertex row 0: 256 does not fit a uchar"},
      {write_file("bad12.ply", "ply\nformat ascii 1.0\n" + xyz + "end_header\n0.5 0.5 0.5\n1.5 1.5 1.5\n2.5 2.5\n"),
       "element vertex row 2 is cut short"},
      {write_file("bad13.ply", "ply\nformat ascii 1.0\n" + xyz + "end_header\n0 0 0\n1 1 1e39\n2 2 2\n"),
       "1e39 does not fit a float"},
      {write_file("bad14.ply", "ply\nformat ascii 1.0\n" + xyz), "no end_header line"},
      {write_file("bad15.ply", "PLY\n"), "is not a PLY file"},
      {write_file("bad16.ply", "ply\nformat ascii 1.0\n" + xyz + "end_header\n0 0 0\n1 1 1\n2 nan 2\n"),
       "vertex 2 has a non-finite y"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.message);
    try {
      read_mesh_ply(c.file);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(c.message), std::string::npos) << e.what();
    }
  }
  try {
    read_particles_ply(binary_ply("not_particles.ply", xyz, verts));
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is not a particle file of `seamless run` (its vertices have no vx"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace seamless
