// What the renderer draws besides the scene: one frame of the particle simulation.
// The spans are read during Renderer::draw only (no copies kept).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "core/geometry.hpp"
#include "core/math.hpp"

namespace seamless {

// A rigid body's surface in its body frame (the frame of its rest offsets q), shaded smooth or
// flat as its normals say. The renderer uploads each one once (keyed by the object).
struct BodyMesh {
  std::vector<vec3> positions, normals;
  std::vector<int3> triangles;
};

// A rigid body in its shape-matching frame (Mueller 2005: x = R q + c): its mesh, or without one
// a box of the given half extents.
struct RigidDraw {
  SE3 world_T_body = SE3::identity();
  vec3 half_extents{0.1f, 0.1f, 0.1f};
  std::shared_ptr<const BodyMesh> mesh;  // null: the box
};

// A cloth sheet: triangles indexing DrawList::positions (solver particle ids).
struct ClothDraw {
  std::vector<int3> triangles;
};

struct DrawList {
  std::span<const vec3> positions;        // dynamic particles, solver id order
  std::span<const std::uint32_t> phases;  // kernels::phase words, same length
  float particle_radius = 0.02f;          // metres
  std::vector<RigidDraw> rigids;
  std::vector<ClothDraw> cloths;
};

// Rigid boxes from the solver's shape-matching frames: each box bounds its body's particles in
// the body frame (plus one radius, the particles' extent). `state` must outlive the DrawList.
// Area-weighted vertex normals of a triangle mesh (smooth shading; zero-area or unused vertices
// get (0, 0, 0)).
std::vector<vec3> vertex_normals(const std::vector<vec3>& positions, const std::vector<int3>& triangles);

DrawList make_draw_list(const ParticleState& state, const std::vector<RigidFrame>& frames, float particle_radius);

}  // namespace seamless
