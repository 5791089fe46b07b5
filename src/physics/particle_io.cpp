#include "physics/particle_io.hpp"

#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless {

void write_objects(const std::string& path, const SceneObjects& o) {
  std::ofstream out(path);
  if (!out) throw Error("cannot write '" + path + "'; check that the folder exists and is writable");
  std::size_t triangles = 0;
  for (const ClothSheet& c : o.cloths) triangles += c.triangles.size();
  out << "# seamless run objects: cloth triangles and rigid bodies in particle ids (docs/RENDERING.md)\n";
  out << "cloth_triangles " << triangles << "\n";
  for (const ClothSheet& c : o.cloths)
    for (const int3& t : c.triangles) out << t.x << ' ' << t.y << ' ' << t.z << '\n';
  out.precision(9);
  for (const RigidBody& b : o.bodies) {
    out << "body " << b.first << ' ' << b.count << ' ' << b.spawn << '\n';
    for (const vec3& q : b.rest) out << q.x << ' ' << q.y << ' ' << q.z << '\n';
  }
  if (!out) throw Error("writing '" + path + "' failed (disk full?)");
}

SceneObjects read_objects(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open '" + path + "' (`seamless run` writes it; older runs have none)");
  SceneObjects o;
  std::string line;
  int lineno = 0;
  auto next = [&](const char* what) -> std::istringstream {
    while (std::getline(in, line)) {
      ++lineno;
      if (!line.empty() && line[0] != '#') return std::istringstream(line);
    }
    throw Error(path + ": ends early, expected " + what);
  };
  auto bad = [&](const char* what) { return Error(path + ":" + std::to_string(lineno) + ": expected " + what); };
  while (true) {
    std::string tag;
    std::istringstream ls;
    try {
      ls = next("a record");
    } catch (const Error&) {
      break;
    }
    ls >> tag;
    if (tag == "cloth_triangles") {
      std::int64_t n = -1;
      if (!(ls >> n) || n < 0) throw bad("cloth_triangles <count>");
      ClothSheet sheet;
      for (std::int64_t i = 0; i < n; ++i) {
        int3 t{};
        if (!(next("a triangle") >> t.x >> t.y >> t.z)) throw bad("three particle ids");
        sheet.triangles.push_back(t);
      }
      if (!sheet.triangles.empty()) o.cloths.push_back(std::move(sheet));
    } else if (tag == "body") {
      RigidBody b;
      if (!(ls >> b.first >> b.count >> b.spawn) || b.first < 0 || b.count < 1)
        throw bad("body <first> <count> <spawn>");
      for (std::int64_t i = 0; i < b.count; ++i) {
        vec3 q{};
        if (!(next("a rest offset") >> q.x >> q.y >> q.z)) throw bad("three rest offset coordinates");
        b.rest.push_back(q);
      }
      o.bodies.push_back(std::move(b));
    } else {
      throw bad("'cloth_triangles' or 'body'");
    }
  }
  return o;
}

}  // namespace seamless
