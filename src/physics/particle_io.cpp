#include "physics/particle_io.hpp"

#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless {

void write_particles_ply(const std::string& path, const ParticleState& s) {
  std::ofstream out(partial_path(path), std::ios::binary);
  if (!out) throw Error("cannot write particle file '" + path + "'; check that the folder exists and is writable");
  out << "ply\nformat binary_little_endian 1.0\nelement vertex " << s.x.size()
      << "\nproperty float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
         "property float vz\nproperty uint phase\nend_header\n";
  std::vector<char> buf(s.x.size() * 28);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    float f[6] = {s.x[i].x, s.x[i].y, s.x[i].z, s.v[i].x, s.v[i].y, s.v[i].z};
    std::memcpy(&buf[i * 28], f, 24);
    std::memcpy(&buf[i * 28 + 24], &s.phase[i], 4);
  }
  out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
  out.close();
  if (!out) throw Error("writing particle file '" + path + "' failed (disk full?)");
  commit_partial(path);
}

ParticleState read_particles_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open particle file '" + path + "'");
  std::string line, header;
  std::int64_t n = -1;
  while (std::getline(in, line) && line != "end_header") {
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0) n = std::stoll(line.substr(15));
  }
  const char* expected =
      "property float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
      "property float vz\nproperty uint phase\n";
  if (n < 0 || header.find("format binary_little_endian") == std::string::npos ||
      header.find(expected) == std::string::npos)
    throw Error("'" + path + "' is not a particle file of `seamless run` (binary PLY with x y z vx vy vz phase)");
  std::vector<char> buf(static_cast<std::size_t>(n) * 28);
  if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size())))
    throw Error("'" + path + "' is cut short: its header promises " + std::to_string(n) + " particles");
  ParticleState s;
  s.x.resize(n), s.v.resize(n), s.phase.resize(n), s.inv_mass.assign(n, 1.f);
  for (std::int64_t i = 0; i < n; ++i) {
    float f[6];
    std::memcpy(f, &buf[i * 28], 24);
    std::memcpy(&s.phase[i], &buf[i * 28 + 24], 4);
    s.x[i] = {f[0], f[1], f[2]}, s.v[i] = {f[3], f[4], f[5]};
  }
  return s;
}

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
