#include "physics/builders.hpp"

#include <tiny_obj_loader.h>
#include <algorithm>
#include <climits>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "core/basis.hpp"
#include "core/error.hpp"
#include "kernels/physics/constraints.hpp"
#include "kernels/physics/particle_math.hpp"

namespace seamless {

namespace {

int count_along(float extent, float d) { return std::max(1, static_cast<int>(std::floor(extent / d + 0.5f))); }

// Two unit vectors spanning the plane normal to n, (u, w, -n) right-handed: u is the projection of
// the x axis (the y axis where n is near x) onto the plane, so that a cloth hung under gravity -y
// spans x (its rows) and z (its columns). In the terms of core's basis (t1, t2, n): u = -t2, w = -t1.
void plane_basis(vec3 n, vec3& u, vec3& w) {
  vec3 t1, t2;
  orthonormal_basis(n, t1, t2);
  u = -t2, w = -t1;
}

// Exact distance of every occupied cell to the nearest empty one (searching shells of growing
// radius), which gives each rigid particle its SDF value and gradient (Macklin 2014 section 5).
// Occupied cells on the surface get phi = -r (r = half a spacing).
std::vector<vec4> voxel_sdf(const std::vector<int3>& cells, float d) {
  int3 lo = cells[0], hi = cells[0];
  for (int3 c : cells) {
    lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
    hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
  }
  lo = lo - int3{1, 1, 1};
  hi = hi + int3{1, 1, 1};
  int3 n = hi - lo + int3{1, 1, 1};
  std::vector<char> occ(static_cast<std::size_t>(n.x) * n.y * n.z, 0);
  auto at = [&](int3 c) -> char& {
    return occ[(static_cast<std::size_t>(c.z - lo.z) * n.y + (c.y - lo.y)) * n.x + (c.x - lo.x)];
  };
  auto inside = [&](int3 c) {
    return c.x >= lo.x && c.y >= lo.y && c.z >= lo.z && c.x <= hi.x && c.y <= hi.y && c.z <= hi.z ? at(c) : 0;
  };
  for (int3 c : cells) at(c) = 1;
  std::vector<vec4> out;
  out.reserve(cells.size());
  for (int3 c : cells) {
    float best = 1e30f;
    vec3 dir{0.f, 0.f, 0.f};
    for (int k = 1; k <= std::max({n.x, n.y, n.z}) && best > static_cast<float>(k - 1); ++k)
      for (int dz = -k; dz <= k; ++dz)
        for (int dy = -k; dy <= k; ++dy)
          for (int dx = -k; dx <= k; ++dx) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != k) continue;
            if (inside(c + int3{dx, dy, dz})) continue;
            float l = std::sqrt(static_cast<float>(dx * dx + dy * dy + dz * dz));
            vec3 u = vec3{float(dx), float(dy), float(dz)} / l;
            if (l < best - 1e-4f) {
              best = l;
              dir = u;
            } else if (l < best + 1e-4f) {
              dir += u;  // ties (edges, corners): the mean direction
            }
          }
    out.push_back({normalize(dir).x, normalize(dir).y, normalize(dir).z, -(best - 0.5f) * d});
  }
  return out;
}

ParticleBatch rigid_from_cells(const std::vector<int3>& cells, const SpawnParams& s, const SolverParams& p) {
  if (cells.empty() && s.shape == RigidShape::mesh && std::min({s.size.x, s.size.y, s.size.z}) >= p.particle_diameter)
    // Big enough to hold particles: the mesh has no inside (voxelize_obj fills what a closed
    // surface encloses), and no size would change that.
    throw ConfigError("spawn rigid: the mesh " + s.mesh +
                      " encloses no volume: it is open (a single triangle, a sheet, or a surface with holes). A "
                      "rigid body is filled with particles, so its mesh must be closed (watertight); close it in "
                      "a mesh editor, or use shape: box or sphere");
  if (cells.empty())
    throw ConfigError("spawn rigid: shape '" + std::string(enum_name(s.shape)) + "' of size (" +
                      std::to_string(s.size.x) + ", " + std::to_string(s.size.y) + ", " + std::to_string(s.size.z) +
                      ") holds no particle of diameter " + std::to_string(p.particle_diameter) +
                      "; make every extent at least one diameter");
  const float d = p.particle_diameter;
  ParticleBatch b;
  b.kind = ParticleBatch::kRigid;
  // Rest offsets q in double, so that they sum to zero to float precision: shape matching takes
  // the centre as the mean position, and a bias in sum q would move the body every iteration.
  double mean[3] = {0, 0, 0};
  for (int3 c : cells) mean[0] += c.x, mean[1] += c.y, mean[2] += c.z;
  for (double& m : mean) m /= static_cast<double>(cells.size());
  b.rotation = euler_to_quat(s.rotation);
  b.centre = s.position;
  b.stiffness = s.stiffness;
  mat3 R = quat_to_mat(b.rotation);
  float inv_m = 1.f / (s.density * d * d * d);
  for (int3 c : cells) {
    vec3 q{static_cast<float>((c.x - mean[0]) * d), static_cast<float>((c.y - mean[1]) * d),
           static_cast<float>((c.z - mean[2]) * d)};
    b.rest.push_back(q);
    b.x.push_back(R * q + s.position);
    b.v.push_back(s.velocity);
    b.inv_mass.push_back(inv_m);
  }
  b.rsdf = voxel_sdf(cells, d);
  return b;
}

}  // namespace

vec4 euler_to_quat(vec3 deg) {
  const float k = kernels::kPi / 360.f;  // half angle in radians
  vec4 qx{std::sin(deg.x * k), 0.f, 0.f, std::cos(deg.x * k)};
  vec4 qy{0.f, std::sin(deg.y * k), 0.f, std::cos(deg.y * k)};
  vec4 qz{0.f, 0.f, std::sin(deg.z * k), std::cos(deg.z * k)};
  return quat_normalize(quat_mul(qz, quat_mul(qy, qx)));
}

ParticleBatch make_fluid_block(const SpawnParams& s, const SolverParams& p) {
  const float d = p.particle_diameter;
  int nx = count_along(s.size.x, d), ny = count_along(s.size.y, d), nz = count_along(s.size.z, d);
  ParticleBatch b;
  b.kind = ParticleBatch::kFluid;
  float inv_m = 1.f / (p.rest_density * d * d * d);
  vec3 c0 = s.position - vec3{float(nx - 1), float(ny - 1), float(nz - 1)} * (0.5f * d);
  for (int z = 0; z < nz; ++z)
    for (int y = 0; y < ny; ++y)
      for (int x = 0; x < nx; ++x) {
        b.x.push_back(c0 + vec3{float(x), float(y), float(z)} * d);
        b.v.push_back(s.velocity);
        b.inv_mass.push_back(inv_m);
      }
  return b;
}

ParticleBatch make_emitter_layer(const SpawnParams& s, const SolverParams& p) {
  const float d = p.particle_diameter;
  vec3 dir = length(s.velocity) > 0.f ? normalize(s.velocity) : -p.up();
  vec3 u, w;
  plane_basis(dir, u, w);
  int k = static_cast<int>(std::floor(s.nozzle_radius / d));
  ParticleBatch b;
  b.kind = ParticleBatch::kFluid;
  float inv_m = 1.f / (p.rest_density * d * d * d);
  for (int j = -k; j <= k; ++j)
    for (int i = -k; i <= k; ++i) {
      if (static_cast<float>(i * i + j * j) * d * d > s.nozzle_radius * s.nozzle_radius + 1e-9f && (i || j)) continue;
      b.x.push_back(s.position + u * (float(i) * d) + w * (float(j) * d));
      b.v.push_back(s.velocity);
      b.inv_mass.push_back(inv_m);
    }
  return b;
}

ParticleBatch make_cloth(const SpawnParams& s, const SolverParams& p) {
  const float d = p.particle_diameter, sp = s.spacing > 0.f ? s.spacing : d;
  const int nx = s.nx, ny = s.ny;
  ParticleBatch b;
  b.kind = ParticleBatch::kCloth;
  b.self_collide = s.self_collide;
  vec3 up = p.up(), u, w;
  plane_basis(up, u, w);
  mat3 R = quat_to_mat(euler_to_quat(s.rotation));
  float inv_m = 1.f / (s.density * d * d * d);
  auto id = [nx](int i, int j) { return j * nx + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      vec3 l = u * ((i - 0.5f * (nx - 1)) * sp) + w * ((j - 0.5f * (ny - 1)) * sp);
      b.x.push_back(s.position + R * l);
      b.v.push_back(s.velocity);
      b.inv_mass.push_back(inv_m);
      b.rest.push_back({i * sp, j * sp, 0.f});
    }
  const int corner[4] = {id(0, 0), id(nx - 1, 0), id(0, ny - 1), id(nx - 1, ny - 1)};
  for (int c : s.pinned) b.inv_mass[corner[c]] = 0.f;
  auto edge = [&](int a, int c) {
    b.edge_a.push_back(a);
    b.edge_b.push_back(c);
    b.edge_len.push_back(length(b.x[a] - b.x[c]));
  };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      if (i + 1 < nx) edge(id(i, j), id(i + 1, j));
      if (j + 1 < ny) edge(id(i, j), id(i, j + 1));
      if (i + 1 < nx && j + 1 < ny) {
        edge(id(i, j), id(i + 1, j + 1));
        edge(id(i + 1, j), id(i, j + 1));
        b.tris.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1)});
        b.tris.push_back({id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      }
    }
  // Bending across every edge shared by two triangles; rest angle from the initial shape.
  std::map<std::pair<int, int>, std::vector<int>> opposite;
  for (const int3& t : b.tris) {
    int v[3] = {t.x, t.y, t.z};
    for (int k = 0; k < 3; ++k) {
      int a = v[k], c = v[(k + 1) % 3], o = v[(k + 2) % 3];
      opposite[{std::min(a, c), std::max(a, c)}].push_back(o);
    }
  }
  for (const auto& [e, o] : opposite) {
    if (o.size() != 2) continue;
    kernels::Quad q{e.first, e.second, o[0], o[1]};
    vec3 p2 = b.x[q.b] - b.x[q.a], n1 = normalize(cross(p2, b.x[q.c] - b.x[q.a])),
         n2 = normalize(cross(p2, b.x[q.d] - b.x[q.a]));
    b.bends.push_back(q);
    b.bend_rest.push_back(std::acos(std::clamp(dot(n1, n2), -1.f, 1.f)));
  }
  b.stretch_k = s.stiffness;
  b.bend_k = s.bend_stiffness;
  b.max_strain = s.max_strain;
  return b;
}

ParticleBatch make_rigid(const SpawnParams& s, const SolverParams& p) {
  const float d = p.particle_diameter;
  std::vector<int3> cells;
  if (s.shape == RigidShape::box) {
    int nx = count_along(s.size.x, d), ny = count_along(s.size.y, d), nz = count_along(s.size.z, d);
    for (int z = 0; z < nz; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) cells.push_back({x, y, z});
  } else if (s.shape == RigidShape::sphere) {
    float R = 0.5f * s.size.x - 0.5f * d;  // particle centres, so that the surface is at size.x / 2
    int k = static_cast<int>(std::ceil(R / d)) + 1;
    for (int z = -k; z <= k; ++z)
      for (int y = -k; y <= k; ++y)
        for (int x = -k; x <= k; ++x)
          if (static_cast<float>(x * x + y * y + z * z) * d * d <= R * R + 1e-6f * d * d) cells.push_back({x, y, z});
  } else {
    // A loaded config was checked already (SpawnParams::validate); this is for entries built in code.
    if (s.mesh.empty()) throw ConfigError("spawn rigid: shape 'mesh' needs the key 'mesh' (an OBJ file path)");
    for (vec3 q : voxelize_obj(s.mesh, d, s.size)) cells.push_back(floor_to_int(q / d + vec3{0.5f, 0.5f, 0.5f}));
  }
  return rigid_from_cells(cells, s, p);
}

std::int64_t spawn_particle_count(const SpawnParams& s, const SolverParams& p) {
  const float d = p.particle_diameter;
  if (s.kind == SpawnKind::fluid_block)
    return std::int64_t{count_along(s.size.x, d)} * count_along(s.size.y, d) * count_along(s.size.z, d);
  if (s.kind == SpawnKind::cloth) return std::int64_t{s.nx} * s.ny;
  if (s.kind == SpawnKind::rigid) return make_rigid(s, p).size();
  if (s.duration <= 0.f) return -1;
  return static_cast<std::int64_t>(std::ceil(s.rate * s.duration)) + make_emitter_layer(s, p).size();
}

void check_spawn_capacity(const std::vector<SpawnParams>& spawns, const SolverParams& p) {
  std::int64_t total = 0;
  for (std::size_t i = 0; i < spawns.size(); ++i) {
    std::int64_t n = spawn_particle_count(spawns[i], p);
    if (n > 0) total += n;
    if (total > p.max_particles)
      throw ConfigError("spawn[" + std::to_string(i) + "] (" + enum_name(spawns[i].kind) +
                        ") brings the particle count to " + std::to_string(total) +
                        ", over solver.max_particles = " + std::to_string(p.max_particles) +
                        "; raise solver.max_particles or make the spawn entries smaller");
  }
}

namespace {

// tinyobjloader's warnings and errors as one line: each message ends in a newline (a few in "\n.").
std::string one_line(const std::string& text) {
  std::string out;
  std::istringstream lines(text);
  for (std::string l; std::getline(lines, l);)
    if (l.find_first_not_of(" .") != std::string::npos) out += (out.empty() ? "" : "; ") + l;
  return out;
}

// The triangles of one tinyobjloader mesh, each polygon as a fan around its first vertex.
// `face` counts the file's faces (of three vertices or more) for the messages: the library checks
// indices only once the file is read and names its last line, so our messages name the face.
void add_fans(const tinyobj::mesh_t& mesh, int nv, const std::string& where, std::size_t& face,
              std::vector<int3>& out) {
  // The library counts a face's vertices in a byte: a face of 256 or more vertices comes back
  // with a wrong count, and the counts no longer add up to the indices.
  std::size_t total = 0;
  for (const unsigned char n : mesh.num_face_vertices) total += n;
  if (total != mesh.indices.size())
    throw InputError(where + ": a face has 256 vertices or more, more than tinyobjloader can read");
  std::size_t at = 0;
  for (const unsigned char n : mesh.num_face_vertices) {
    ++face;
    std::vector<int> idx;
    for (std::size_t k = at; k < at + n; ++k) {
      const int i = mesh.indices[k].vertex_index;
      // A negative index counts back from the vertices defined before the face; the library
      // resolves it, so one that counted back too far arrives below 0.
      if (i < 0)
        throw InputError(where + ": face " + std::to_string(face) +
                         " has a negative vertex number that counts back past the first vertex");
      if (i >= nv)
        throw InputError(where + ": face " + std::to_string(face) + ": face vertex " + std::to_string(i + 1LL) +
                         " does not exist (the file has " + std::to_string(nv) + " vertices)");
      idx.push_back(i);
    }
    for (std::size_t k = 2; k < idx.size(); ++k) out.push_back({idx[0], idx[k - 1], idx[k]});
    at += n;
  }
}

}  // namespace

ObjMesh read_obj(const std::string& path) {
  const std::string where = "mesh file '" + path + "'";
  std::ifstream in(path);
  if (!in) throw InputError("cannot open " + where + " (spawn rigid, shape: mesh); check the path");
  tinyobj::attrib_t attrib;
  std::vector<tinyobj::shape_t> shapes;
  std::vector<tinyobj::material_t> materials;
  std::string warn, err;
  // No material reader: a body needs only the triangles, and an 'mtllib' line must not make the
  // reader open other files. The library does not triangulate (it would split quads along their
  // shorter diagonal and ear-clip larger polygons): the fans below are what ObjMesh promises.
  if (!tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr, /*triangulate=*/false,
                        /*default_vcols_fallback=*/false))
    throw InputError(where + " is not an OBJ file tinyobjloader can read: " +
                     (err.empty() && warn.empty() ? "it gives no reason" : one_line(err + warn)));

  ObjMesh m;
  if (attrib.vertices.size() / 3 > static_cast<std::size_t>(INT_MAX))
    throw InputError(where + " has more vertices than an int can count");
  for (std::size_t i = 0; i + 2 < attrib.vertices.size(); i += 3) {
    const vec3 p{attrib.vertices[i], attrib.vertices[i + 1], attrib.vertices[i + 2]};
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
      throw InputError(where + ": vertex " + std::to_string(i / 3 + 1) + " is not a finite point (" +
                       std::to_string(p.x) + ", " + std::to_string(p.y) + ", " + std::to_string(p.z) + ")");
    m.v.push_back(p);
  }
  std::size_t face = 0;
  for (const tinyobj::shape_t& s : shapes) add_fans(s.mesh, static_cast<int>(m.v.size()), where, face, m.f);
  if (m.v.empty() || m.f.empty())
    throw InputError(where + " has no triangles (expected OBJ 'v' and 'f' lines" +
                     (warn.empty() ? "" : "; tinyobjloader: " + one_line(warn)) + ")");
  return m;
}

std::vector<vec3> voxelize_obj(const std::string& path, float spacing, vec3 fit_size) {
  ObjMesh m = read_obj(path);
  vec3 lo = m.v[0], hi = m.v[0];
  for (vec3 p : m.v) {
    lo = vmin(lo, p);
    hi = vmax(hi, p);
  }
  vec3 ext = hi - lo, mid = (lo + hi) * 0.5f;
  float scale = std::min(
      {fit_size.x / std::max(ext.x, 1e-9f), fit_size.y / std::max(ext.y, 1e-9f), fit_size.z / std::max(ext.z, 1e-9f)});
  for (vec3& p : m.v) p = (p - mid) * scale;
  ext = ext * scale;
  int ny = static_cast<int>(ext.y / spacing) + 1, nz = static_cast<int>(ext.z / spacing) + 1;
  std::vector<vec3> out;
  // Ray parity along +x for every (y, z) row of cell centres.
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j) {
      float y = (j - 0.5f * (ny - 1)) * spacing, z = (k - 0.5f * (nz - 1)) * spacing;
      std::vector<float> xs;
      for (const int3& t : m.f) {
        vec3 a = m.v[t.x], b = m.v[t.y], c = m.v[t.z];
        float det = (b.y - a.y) * (c.z - a.z) - (c.y - a.y) * (b.z - a.z);
        if (std::fabs(det) < 1e-12f) continue;
        float u = ((y - a.y) * (c.z - a.z) - (c.y - a.y) * (z - a.z)) / det;
        float v = ((b.y - a.y) * (z - a.z) - (y - a.y) * (b.z - a.z)) / det;
        if (u < 0.f || v < 0.f || u + v > 1.f) continue;
        xs.push_back(a.x + u * (b.x - a.x) + v * (c.x - a.x));
      }
      std::sort(xs.begin(), xs.end());
      for (std::size_t q = 0; q + 1 < xs.size(); q += 2) {
        int i0 = static_cast<int>(std::ceil(xs[q] / spacing)), i1 = static_cast<int>(std::floor(xs[q + 1] / spacing));
        for (int i = i0; i <= i1; ++i) out.push_back({i * spacing, y, z});
      }
    }
  return out;
}

}  // namespace seamless
