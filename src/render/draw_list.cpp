#include "render/draw_list.hpp"

#include <cmath>

#include "core/quaternion.hpp"

namespace seamless {

namespace {

std::vector<RigidDraw> rigid_draws(const SceneObjects& objects, const std::vector<RigidFrame>& frames, float radius) {
  std::vector<RigidDraw> out;
  for (const RigidFrame& f : frames)
    for (const RigidBody& body : objects.bodies) {
      if (body.first != f.first) continue;
      RigidDraw r;
      r.world_T_body = {quat_to_mat(f.rotation), f.centre};
      vec3 hi{0.f, 0.f, 0.f};  // the box around the rest offsets, plus the particles' radius
      for (vec3 q : body.rest) hi = vmax(hi, vec3{std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
      r.half_extents = hi + vec3{radius, radius, radius};
      r.mesh = body.mesh;
      out.push_back(std::move(r));
    }
  return out;
}

}  // namespace

DrawList make_draw_list(std::span<const vec3> positions, std::span<const std::uint32_t> phases, std::int64_t particles,
                        const SceneObjects& objects, const std::vector<RigidFrame>& frames, float radius) {
  DrawList d;
  d.positions = positions, d.phases = phases, d.particle_radius = radius;
  d.rigids = rigid_draws(objects, frames, radius);
  ClothDraw cloth;
  for (const ClothSheet& sheet : objects.cloths)
    for (const int3& t : sheet.triangles)
      if (t.x < particles && t.y < particles && t.z < particles) cloth.triangles.push_back(t);
  if (!cloth.triangles.empty()) d.cloths.push_back(std::move(cloth));
  return d;
}

DrawList make_draw_list(const ParticleState& state, const SceneObjects& objects, const std::vector<RigidFrame>& frames,
                        float radius) {
  return make_draw_list(state.x, state.phase, static_cast<std::int64_t>(state.x.size()), objects, frames, radius);
}

Box3 body_box(const RigidDraw& r) {
  if (r.mesh && !r.mesh->positions.empty()) return point_bounds(r.mesh->positions);
  return {r.half_extents * -1.f, r.half_extents};
}

}  // namespace seamless
