#include "recon/ply.hpp"

#include <cstring>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless {

void write_ply(const std::string& path, const Mesh& mesh) {
  std::ofstream f(partial_path(path), std::ios::binary);
  if (!f) throw Error("cannot write mesh to '" + path + "' (does the folder exist and is it writable?)");
  const bool normals = mesh.normals.size() == mesh.positions.size();
  const bool colors = mesh.colors.size() == mesh.positions.size();
  f << "ply\nformat binary_little_endian 1.0\ncomment written by seamless\n";
  f << "element vertex " << mesh.positions.size() << "\nproperty float x\nproperty float y\nproperty float z\n";
  if (normals) f << "property float nx\nproperty float ny\nproperty float nz\n";
  if (colors) f << "property uchar red\nproperty uchar green\nproperty uchar blue\n";
  f << "element face " << mesh.triangles.size() << "\nproperty list uchar int vertex_indices\nend_header\n";
  std::vector<char> buf;
  auto put = [&](const void* p, std::size_t n) { buf.insert(buf.end(), (const char*)p, (const char*)p + n); };
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    put(&mesh.positions[i], 12);
    if (normals) put(&mesh.normals[i], 12);
    if (colors) put(&mesh.colors[i], 3);
  }
  for (const int3& t : mesh.triangles) {
    std::uint8_t three = 3;
    put(&three, 1);
    put(&t, 12);
  }
  f.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  f.close();
  if (!f) throw Error("writing mesh to '" + path + "' failed (disk full?)");
  commit_partial(path);
}

namespace {
struct Prop {
  std::string type, name;
};
std::size_t type_size(const std::string& t, const std::string& path) {
  if (t == "float" || t == "float32" || t == "int" || t == "int32" || t == "uint" || t == "uint32") return 4;
  if (t == "uchar" || t == "uint8" || t == "char" || t == "int8") return 1;
  if (t == "double" || t == "float64") return 8;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  throw InputError("PLY '" + path + "': unsupported property type '" + t + "'");
}
}  // namespace

Mesh read_ply(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError("cannot open mesh '" + path + "'");
  std::string line;
  std::getline(f, line);
  if (line != "ply") throw InputError("'" + path + "' is not a PLY file (first line is not 'ply')");
  std::size_t nv = 0, nf = 0;
  std::vector<Prop> vprops;
  std::string element, face_count = "uchar", face_index = "int";
  while (std::getline(f, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string word;
    ls >> word;
    if (word == "format") {
      std::string fmt;
      ls >> fmt;
      if (fmt != "binary_little_endian")
        throw InputError("PLY '" + path + "': format " + fmt + " is not supported (only binary_little_endian)");
    } else if (word == "element") {
      std::size_t n = 0;
      ls >> element >> n;
      (element == "vertex" ? nv : nf) = n;
      if (element != "vertex" && element != "face")
        throw InputError("PLY '" + path + "': element '" + element + "' is not supported");
    } else if (word == "property") {
      std::string t, name;
      ls >> t;
      if (t == "list") {
        ls >> face_count >> face_index;
        if (type_size(face_count, path) != 1 || type_size(face_index, path) != 4)
          throw InputError("PLY '" + path + "': face lists must be 'list uchar int'");
      } else if (element == "vertex") {
        ls >> name;
        vprops.push_back({t, name});
      }
    }
  }
  Mesh m;
  m.positions.resize(nv);
  bool has_n = false, has_c = false;
  for (const Prop& p : vprops) has_n |= p.name == "nx", has_c |= p.name == "red";
  if (has_n) m.normals.resize(nv);
  if (has_c) m.colors.resize(nv);
  std::size_t stride = 0;
  for (const Prop& p : vprops) stride += type_size(p.type, path);
  std::vector<char> rec(stride);
  for (std::size_t i = 0; i < nv; ++i) {
    if (!f.read(rec.data(), static_cast<std::streamsize>(stride))) throw InputError("PLY '" + path + "': truncated vertex data");
    std::size_t off = 0;
    for (const Prop& p : vprops) {
      float v = 0.f;
      if (p.type == "float" || p.type == "float32") std::memcpy(&v, rec.data() + off, 4);
      else if (p.type == "uchar" || p.type == "uint8") v = static_cast<std::uint8_t>(rec[off]);
      const std::string& n = p.name;
      if (n == "x") m.positions[i].x = v;
      if (n == "y") m.positions[i].y = v;
      if (n == "z") m.positions[i].z = v;
      if (n == "nx") m.normals[i].x = v;
      if (n == "ny") m.normals[i].y = v;
      if (n == "nz") m.normals[i].z = v;
      if (n == "red") m.colors[i].x = static_cast<std::uint8_t>(v);
      if (n == "green") m.colors[i].y = static_cast<std::uint8_t>(v);
      if (n == "blue") m.colors[i].z = static_cast<std::uint8_t>(v);
      off += type_size(p.type, path);
    }
  }
  m.triangles.resize(nf);
  for (std::size_t i = 0; i < nf; ++i) {
    std::uint8_t count = 0;
    f.read(reinterpret_cast<char*>(&count), 1);
    if (count != 3) throw InputError("PLY '" + path + "': face " + std::to_string(i) + " is not a triangle");
    if (!f.read(reinterpret_cast<char*>(&m.triangles[i]), 12)) throw InputError("PLY '" + path + "': truncated face data");
  }
  return m;
}

}  // namespace seamless
