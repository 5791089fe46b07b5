#include "physics/objects.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>

#include "core/error.hpp"
#include "kernels/physics/particle_math.hpp"
#include "physics/builders.hpp"

namespace seamless {

void SpawnSchedule::add(const std::vector<SpawnParams>& spawns) {
  for (const SpawnParams& s : spawns) pending_.push_back({added_++, s});
}

void SpawnSchedule::spawn_due(double time, const Gate& gate, const std::function<void(const Entry&)>& spawn) {
  for (auto it = pending_.begin(); it != pending_.end();)
    if (it->s.time <= time + 1e-9 && (!gate || gate(it->index, it->s))) {
      const Entry e = std::move(*it);
      it = pending_.erase(it);
      spawn(e);
    } else {
      ++it;
    }
}

std::optional<SpawnSchedule::Entry> SpawnSchedule::take_next() {
  if (pending_.empty()) return std::nullopt;
  auto it = std::min_element(pending_.begin(), pending_.end(),
                             [](const Entry& a, const Entry& b) { return a.s.time < b.s.time; });
  Entry e = std::move(*it);
  pending_.erase(it);
  return e;
}

namespace {

// UV sphere with outward normals, 16 rings of 32 segments (smooth at the frame sizes used).
std::shared_ptr<const BodyMesh> sphere_mesh(float r) {
  auto m = std::make_shared<BodyMesh>();
  const int rings = 16, segs = 32;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segs; ++j) {
      const float th = kernels::kPi * i / rings, ph = 2.f * kernels::kPi * j / segs;
      const vec3 n{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
      m->positions.push_back(n * r), m->normals.push_back(n);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const int a = i * (segs + 1) + j, b = a + segs + 1;
      m->triangles.push_back({a, a + 1, b}), m->triangles.push_back({a + 1, b + 1, b});
    }
  return m;
}

// The OBJ of a `shape: mesh` body in its body frame. The builder centres the OBJ on its bounding
// box, scales it to fit s.size and voxelises it (voxelize_obj); the rest offsets are the voxel
// centres minus their mean, so the body frame's origin is that mean in the scaled OBJ's frame.
std::shared_ptr<const BodyMesh> obj_body_mesh(const SpawnParams& s, const SolverParams& p) {
  const ObjMesh obj = read_obj(s.mesh);
  auto m = std::make_shared<BodyMesh>();
  m->positions = obj.v, m->triangles = obj.f;
  vec3 lo = m->positions[0], hi = lo;
  for (vec3 v : m->positions) lo = vmin(lo, v), hi = vmax(hi, v);
  const vec3 ext = hi - lo, mid = (lo + hi) * 0.5f;
  const float scale = std::min(
      {s.size.x / std::max(ext.x, 1e-9f), s.size.y / std::max(ext.y, 1e-9f), s.size.z / std::max(ext.z, 1e-9f)});
  vec3 mean{0.f, 0.f, 0.f};
  const std::vector<vec3> cells = voxelize_obj(s.mesh, p.particle_diameter, s.size);
  for (vec3 c : cells) mean += c;
  if (!cells.empty()) mean = mean / static_cast<float>(cells.size());
  for (vec3& v : m->positions) v = (v - mid) * scale - mean;
  m->normals = vertex_normals(m->positions, m->triangles);
  return m;
}

}  // namespace

std::shared_ptr<const BodyMesh> body_mesh(const SpawnParams& s, const SolverParams& p) {
  if (s.kind != SpawnKind::rigid) return nullptr;
  if (s.shape == RigidShape::sphere) return sphere_mesh(0.5f * s.size.x);
  if (s.shape == RigidShape::mesh) return obj_body_mesh(s, p);
  return nullptr;
}

void attach_body_meshes(SceneObjects& objects, const std::vector<SpawnParams>& spawns, const SolverParams& p) {
  for (RigidBody& b : objects.bodies) {
    if (b.spawn < 0 || b.spawn >= static_cast<int>(spawns.size())) continue;
    try {
      b.mesh = body_mesh(spawns[b.spawn], p);
    } catch (const Error& e) {
      spdlog::warn("rigid body mesh '{}' cannot be read here ({}): drawing that body as a box", spawns[b.spawn].mesh,
                   e.what());
    }
  }
}

std::vector<RigidFrame> rigid_frames_of_state(const SceneObjects& o, const ParticleState& s, std::vector<vec4>& warm) {
  warm.resize(o.bodies.size(), vec4{0.f, 0.f, 0.f, 1.f});
  std::vector<RigidFrame> out;
  for (std::size_t b = 0; b < o.bodies.size(); ++b) {
    const RigidBody& body = o.bodies[b];
    if (body.first + body.count > static_cast<std::int64_t>(s.x.size())) continue;  // not spawned yet
    vec3 c{0.f, 0.f, 0.f};
    for (std::int64_t i = 0; i < body.count; ++i) c += s.x[body.first + i];
    c = c / static_cast<float>(body.count);
    mat3 A = mat3::zero();
    for (std::int64_t i = 0; i < body.count; ++i) A = A + outer(s.x[body.first + i] - c, body.rest[i]);
    // 64 iterations: enough from identity for any rotation (each turns by the full residual angle).
    warm[b] = kernels::extract_rotation(A, warm[b], 64);
    out.push_back({c, warm[b], body.first, body.count});
  }
  return out;
}

}  // namespace seamless
