#include "render/draw_list.hpp"

#include <algorithm>
#include <cmath>

#include "core/geometry.hpp"
#include "kernels/physics/particle_math.hpp"

namespace seamless {

// Sum over the triangles around each vertex of their normals scaled by twice their area.
std::vector<vec3> vertex_normals(const std::vector<vec3>& p, const std::vector<int3>& tris) {
  std::vector<vec3> n(p.size(), vec3{0.f, 0.f, 0.f});
  for (const int3& t : tris) {
    const vec3 c = cross(p[t.y] - p[t.x], p[t.z] - p[t.x]);  // |c| = twice the area
    n[t.x] += c, n[t.y] += c, n[t.z] += c;
  }
  for (vec3& v : n) {
    const float l = length(v);
    v = l > 0.f ? v / l : vec3{0.f, 0.f, 0.f};
  }
  return n;
}

DrawList make_draw_list(const ParticleState& state, const std::vector<RigidFrame>& frames, float radius) {
  DrawList d;
  d.positions = state.x;
  d.phases = state.phase;
  d.particle_radius = radius;
  for (const RigidFrame& f : frames) {
    RigidDraw r;
    r.world_T_body = {kernels::quat_to_mat(f.rotation), f.centre};
    const mat3 Rt = transpose(r.world_T_body.R);
    vec3 hi{0.f, 0.f, 0.f};
    const auto end = std::min<std::int64_t>(f.first + f.count, static_cast<std::int64_t>(state.x.size()));
    for (std::int64_t i = f.first; i < end; ++i) {
      const vec3 q = Rt * (state.x[static_cast<std::size_t>(i)] - f.centre);
      hi = vmax(hi, vec3{std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
    }
    r.half_extents = hi + vec3{radius, radius, radius};
    d.rigids.push_back(r);
  }
  return d;
}

}  // namespace seamless
