// Geometry that several layers hand each other: the reconstructed mesh (recon makes it, render and
// physics read it) and the particle state and rigid-body frames (physics makes them, render and the
// app read them). Kept in core so that render depends on core and kernels only.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.hpp"

namespace seamless {

// A triangle mesh; normals and colors are per vertex and may be empty.
struct Mesh {
  std::vector<vec3> positions;
  std::vector<vec3> normals;
  std::vector<uchar3> colors;
  std::vector<int3> triangles;
};

// Particle state in id order (ids are given in spawn order and never change).
struct ParticleState {
  std::vector<vec3> x, v;
  std::vector<float> inv_mass;
  std::vector<std::uint32_t> phase;  // kernels::phase flags and group
};

// One rigid body's frame: x = R q + c for its rest offsets q.
struct RigidFrame {
  vec3 centre;
  vec4 rotation;  // quaternion (x, y, z, w)
  std::int64_t first = 0, count = 0;  // particle ids
};

}  // namespace seamless
