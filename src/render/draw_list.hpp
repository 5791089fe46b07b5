// What the renderer draws besides the scene: one frame of the particle simulation.
// The spans are read during Renderer::draw only (no copies kept).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include "core/math.hpp"

namespace seamless {

struct ParticleState;
struct RigidFrame;

// A rigid body drawn as a box in its shape-matching frame (Mueller 2005: x = R q + c).
struct RigidDraw {
  SE3 world_T_body = SE3::identity();
  vec3 half_extents{0.1f, 0.1f, 0.1f};
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
DrawList make_draw_list(const ParticleState& state, const std::vector<RigidFrame>& frames, float particle_radius);

}  // namespace seamless
