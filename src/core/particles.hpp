// The particle solver's state and objects as the layers hand them to each other: physics makes
// them (ParticleSolver, or read_objects for a finished run), render and the app read them. In core
// so that render depends on core and kernels only; the solver itself is in physics.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/math.hpp"
#include "core/mesh.hpp"

namespace seamless {

// Particle state in id order (ids are given in spawn order and never change).
struct ParticleState {
  std::vector<vec3> x, v;
  std::vector<float> inv_mass;
  std::vector<std::uint32_t> phase;  // phase flags and group (core/phase.hpp)
};

// One rigid body's frame: x = R q + c for its rest offsets q.
struct RigidFrame {
  vec3 centre;
  vec4 rotation;                      // quaternion (x, y, z, w)
  std::int64_t first = 0, count = 0;  // particle ids
};

// The objects the particle solver has created (physics makes them: ParticleSolver::objects(), or
// read_objects for a finished run). Particle ids are given in spawn order and never change.
struct RigidBody {
  std::int64_t first = 0, count = 0;     // particle ids
  int spawn = -1;                        // index into the experiment's spawn list; -1: none (a batch added directly)
  std::vector<vec3> rest;                // body-frame offsets q, x = R q + c (Mueller et al. 2005)
  std::shared_ptr<const BodyMesh> mesh;  // the surface in the body frame; null: drawn as the box around `rest`
};
struct ClothSheet {
  std::int64_t first = 0, count = 0;  // particle ids (count 0: not known, a sheet read from objects.txt)
  int spawn = -1;                     // as RigidBody::spawn
  std::vector<int3> triangles;        // particle ids
};
struct SceneObjects {
  std::vector<RigidBody> bodies;   // in the order the solver created them (its body index)
  std::vector<ClothSheet> cloths;  // likewise
};

}  // namespace seamless
