// PLY files (Turk's polygon file format, as Stanford's scanning repository and most mesh tools use
// it): the one reader and writer of the meshes (mesh.ply) and particle states (particles*.ply) that
// seamless writes and reads back. Reads all three encodings (ascii, binary_little_endian,
// binary_big_endian) and any element, property and scalar type; writes binary in this machine's
// byte order. Bad files are InputErrors naming the file and the problem.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "core/mesh.hpp"
#include "core/particles.hpp"

namespace seamless {

// ---- what seamless stores --------------------------------------------------------------------

// Vertices with float x y z, float nx ny nz when mesh has a normal per vertex, uchar red green
// blue when it has a colour per vertex; faces as `list uchar int vertex_indices`.
void write_mesh_ply(const std::string& path, const Mesh& mesh);
// Any PLY mesh of triangles: vertex x y z (required), nx ny nz and red green blue (0-255) when
// present (any one of them makes the attribute, the others stay 0), other vertex properties and
// other elements skipped; faces as a list of 3 integer indices (vertex_indices or vertex_index).
Mesh read_mesh_ply(const std::string& path);

// Vertices with float x y z vx vy vz and uint phase (core/phase.hpp).
void write_particles_ply(const std::string& path, const ParticleState& s);
// A PLY whose vertices have x y z vx vy vz phase (inv_mass is not stored: 1).
ParticleState read_particles_ply(const std::string& path);

// ---- the tables of any PLY file --------------------------------------------------------------

enum class PlyType : std::uint8_t { i8, u8, i16, u16, i32, u32, f32, f64 };
enum class PlyFormat : std::uint8_t { ascii, binary_little_endian, binary_big_endian };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::f32;  // the value's type; a list's item type
  bool list = false;
  PlyType count_type = PlyType::u8;  // a list's length type
  // After reading: the values of every row in this machine's byte order, type's size each. A
  // list's items of every row one after the other, row r's at [starts[r], starts[r + 1]).
  std::vector<unsigned char> bytes;
  std::vector<std::int64_t> starts;

  double value(std::int64_t i) const;  // value (or list item) i; every PLY type fits a double
};

struct PlyElement {
  std::string name;
  std::int64_t count = 0;
  std::vector<PlyProperty> properties;
  const PlyProperty* find(std::string_view property) const;  // nullptr when absent
};

struct PlyData {
  PlyFormat format = PlyFormat::binary_little_endian;
  std::vector<PlyElement> elements;
  const PlyElement* find(std::string_view element) const;  // nullptr when absent
};

PlyData read_ply_data(const std::string& path);

// One element to write: `count` rows; each column reads row r at base + r * stride (a list
// column: list_length items of its type there, written with a uchar length).
struct PlyColumn {
  std::string name;
  PlyType type;
  const void* base;
  std::size_t stride;
  int list_length = 0;  // 0: a scalar
};
struct PlyElementOut {
  std::string name;
  std::int64_t count;
  std::vector<PlyColumn> columns;
};
// Binary PLY in this machine's byte order, written as path.partial and renamed; `what` names the
// file's content in errors ("mesh", "particle file").
void write_ply_data(const std::string& path, const std::vector<PlyElementOut>& elements, const std::string& what);

}  // namespace seamless
