// Triangle meshes that several layers hand each other: the reconstructed mesh (recon makes it,
// render, physics and the app read it) and a rigid body's surface (physics makes it, render draws
// it). In core so that render depends on core and kernels only.
#pragma once
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

// A rigid body's surface in its body frame (the frame of its rest offsets q), shaded smooth or
// flat as its normals say. The renderer uploads each one once (keyed by the object).
struct BodyMesh {
  std::vector<vec3> positions, normals;
  std::vector<int3> triangles;
};

// Axis-aligned bounds of points; lo = hi = (0, 0, 0) for none.
struct Box3 {
  vec3 lo{0.f, 0.f, 0.f}, hi{0.f, 0.f, 0.f};
};
Box3 point_bounds(const std::vector<vec3>& points);

// Area-weighted vertex normals of a triangle mesh (smooth shading; zero-area or unused vertices
// get (0, 0, 0)).
std::vector<vec3> vertex_normals(const std::vector<vec3>& positions, const std::vector<int3>& triangles);

}  // namespace seamless
