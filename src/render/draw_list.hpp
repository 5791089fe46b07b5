// What the renderer draws besides the scene: one frame of the particle simulation.
// The spans are read during Renderer::draw only (no copies kept).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/math.hpp"
#include "core/particles.hpp"

namespace seamless {

// A rigid body in its shape-matching frame (Mueller 2005: x = R q + c): its mesh, or without one
// a box of the given half extents.
struct RigidDraw {
  SE3 world_T_body = SE3::identity();
  vec3 half_extents{0.1f, 0.1f, 0.1f};
  std::shared_ptr<const BodyMesh> mesh;  // null: the box
};
// A body's box in its own frame: its mesh's bounds, or +-half_extents without a mesh.
Box3 body_box(const RigidDraw& r);

// A cloth sheet: triangles indexing DrawList::positions (solver particle ids).
struct ClothDraw {
  std::vector<int3> triangles;
};

struct DrawList {
  std::span<const vec3> positions;        // dynamic particles, solver id order
  std::span<const std::uint32_t> phases;  // phase words (core/phase.hpp), same length
  // The fluid's ellipsoids (FluidEllipsoids::kVec4s vec4 per particle, FluidEllipsoids), when the
  // caller has them; empty: the renderer computes them on the CPU if render.fluid_anisotropy is on.
  std::span<const vec4> ellipsoids;
  float particle_radius = 0.02f;  // metres
  // Against gravity, world (physics' up_from_gravity): a lone drop at rest lies flat across it
  // (src/render/shaders/splat.glsl, "Lone drops at rest").
  vec3 up{0.f, 1.f, 0.f};
  std::vector<RigidDraw> rigids;
  std::vector<ClothDraw> cloths;
};

// One frame's DrawList from the solver's objects (physics: ParticleSolver::objects(), or
// read_objects for a finished run) and its rigid frames:
// - the particles as spans into `positions` and `phases` (which must outlive the list; empty when
//   the renderer takes them from the device, Renderer::draw_device_particles);
// - the cloth sheets as one triangle mesh, the triangles of the first `particles` ids (sheets
//   spawned by then);
// - each body in `frames` (matched to `objects` by its first particle id) with its mesh, or without
//   one the box around its rest offsets plus one particle radius (the particles' extent).
DrawList make_draw_list(std::span<const vec3> positions, std::span<const std::uint32_t> phases, std::int64_t particles,
                        const SceneObjects& objects, const std::vector<RigidFrame>& frames, float particle_radius);
// The same for a state in host memory (`state` must outlive the list).
DrawList make_draw_list(const ParticleState& state, const SceneObjects& objects, const std::vector<RigidFrame>& frames,
                        float particle_radius);

}  // namespace seamless
