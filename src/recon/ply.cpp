#include "recon/ply.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
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
// The little-endian value of type t at p, as a double (every PLY scalar type fits).
double read_value(const std::string& t, const char* p) {
  auto get = [p](auto v) {
    std::memcpy(&v, p, sizeof v);
    return static_cast<double>(v);
  };
  if (t == "float" || t == "float32") return get(float{});
  if (t == "double" || t == "float64") return get(double{});
  if (t == "uchar" || t == "uint8") return get(std::uint8_t{});
  if (t == "char" || t == "int8") return get(std::int8_t{});
  if (t == "short" || t == "int16") return get(std::int16_t{});
  if (t == "ushort" || t == "uint16") return get(std::uint16_t{});
  if (t == "int" || t == "int32") return get(std::int32_t{});
  return get(std::uint32_t{});  // uint, uint32 (type_size accepted no other)
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
  bool seen_face = false;
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
      if (element != "vertex" && element != "face")
        throw InputError("PLY '" + path + "': element '" + element + "' is not supported");
      if (element == "vertex" && seen_face)  // the data would be read in the wrong order
        throw InputError("PLY '" + path + "': element vertex must come before element face");
      seen_face |= element == "face";
      (element == "vertex" ? nv : nf) = n;
    } else if (word == "property") {
      std::string t, name;
      ls >> t;
      if (t == "list") {
        if (element != "face")
          throw InputError("PLY '" + path + "': a list property is supported in element face only");
        ls >> face_count >> face_index;
        if (type_size(face_count, path) != 1 || type_size(face_index, path) != 4)
          throw InputError("PLY '" + path + "': face lists must be 'list uchar int'");
      } else if (element == "vertex") {
        ls >> name;
        vprops.push_back({t, name});
      } else {  // its bytes would be read as vertex indices
        throw InputError("PLY '" + path + "': property '" + line + "' outside element vertex is not supported");
      }
    }
  }
  if (line != "end_header") throw InputError("PLY '" + path + "': no end_header line");
  std::size_t stride = 0;
  for (const Prop& p : vprops) stride += type_size(p.type, path);
  for (const char* axis : {"x", "y", "z"})
    if (nv > 0 && std::none_of(vprops.begin(), vprops.end(), [&](const Prop& p) { return p.name == axis; }))
      throw InputError("PLY '" + path + "': the vertices have no property " + axis);
  // The counts come from the header: check them against the file's size before allocating.
  const std::streamoff here = f.tellg();
  f.seekg(0, std::ios::end);
  const auto left = static_cast<std::size_t>(f.tellg() - here);
  f.seekg(here);
  if ((stride > 0 && nv > left / stride) || nf > left / 13 || nv * stride + nf * 13 > left)
    throw InputError("PLY '" + path + "': the header announces " + std::to_string(nv) + " vertices and " +
                     std::to_string(nf) + " faces, more than the file's " + std::to_string(left) +
                     " bytes of data hold (truncated?)");
  Mesh m;
  m.positions.resize(nv);
  bool has_n = false, has_c = false;
  for (const Prop& p : vprops) {  // any one component makes the attribute (the others stay 0)
    has_n |= p.name == "nx" || p.name == "ny" || p.name == "nz";
    has_c |= p.name == "red" || p.name == "green" || p.name == "blue";
  }
  if (has_n) m.normals.resize(nv);
  if (has_c) m.colors.resize(nv);
  std::vector<char> rec(stride);
  for (std::size_t i = 0; i < nv; ++i) {
    if (!f.read(rec.data(), static_cast<std::streamsize>(stride)))
      throw InputError("PLY '" + path + "': truncated vertex data");
    std::size_t off = 0;
    for (const Prop& p : vprops) {
      const double d = read_value(p.type, rec.data() + off);
      const float v = static_cast<float>(d);
      const std::string& n = p.name;
      if ((n == "x" || n == "y" || n == "z" || n == "nx" || n == "ny" || n == "nz") && !std::isfinite(v))
        throw InputError("PLY '" + path + "': vertex " + std::to_string(i) + " has a non-finite " + n);
      if ((n == "red" || n == "green" || n == "blue") && !(d >= 0 && d <= 255))
        throw InputError("PLY '" + path + "': vertex " + std::to_string(i) + " has " + n + " " + std::to_string(d) +
                         ", outside 0..255");
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
    if (!f.read(reinterpret_cast<char*>(&m.triangles[i]), 12))
      throw InputError("PLY '" + path + "': truncated face data");
    for (int k : {m.triangles[i].x, m.triangles[i].y, m.triangles[i].z})
      if (k < 0 || static_cast<std::size_t>(k) >= nv)
        throw InputError("PLY '" + path + "': face " + std::to_string(i) + " refers to vertex " + std::to_string(k) +
                         ", but there are " + std::to_string(nv) + " vertices");
  }
  return m;
}

}  // namespace seamless
