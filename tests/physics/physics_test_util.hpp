// Scene helpers shared by the physics tests.
#pragma once
#include <cmath>
#include <vector>

#include "core/math.hpp"
#include "kernels/physics/particle_math.hpp"
#include "kernels/physics/scene_sdf.hpp"
#include "physics/particle_solver.hpp"

namespace seamless::test {

// A flat layer of static particles at height y, spacing d, covering [x0, x1] x [z0, z1].
inline std::vector<vec3> static_layer(float y, float x0, float x1, float z0, float z1, float d) {
  std::vector<vec3> out;
  for (float z = z0; z <= z1 + 1e-5f; z += d)
    for (float x = x0; x <= x1 + 1e-5f; x += d) out.push_back({x, y, z});
  return out;
}

// Static particles on the walls and floor of an open box [lo, hi] (the particle centres lie on
// the faces; the fluid is inside), spacing d.
inline std::vector<vec3> static_box(vec3 lo, vec3 hi, float d) {
  std::vector<vec3> out;
  int nx = static_cast<int>(std::lround((hi.x - lo.x) / d)), ny = static_cast<int>(std::lround((hi.y - lo.y) / d)),
      nz = static_cast<int>(std::lround((hi.z - lo.z) / d));
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        if (j == 0 || i == 0 || i == nx || k == 0 || k == nz)
          out.push_back(lo + vec3{float(i), float(j), float(k)} * d);
  return out;
}

inline kernels::SceneSdf half_space(vec3 n, float offset) {
  kernels::SceneSdf s;
  s.count = 1;
  s.prims[0].kind = kernels::kSdfHalfSpace;
  s.prims[0].a = normalize(n);
  s.prims[0].b = {offset, 0.f, 0.f};
  s.prims[0].R = mat3::identity();
  return s;
}

struct Momentum {
  double p[3] = {0, 0, 0};
  double magnitude_sum = 0;  // sum of m |v|: the scale that rounding errors compare to
};

inline Momentum momentum(const ParticleState& s) {
  Momentum m;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (!(s.inv_mass[i] > 0.f)) continue;
    double mass = 1.0 / s.inv_mass[i];
    m.p[0] += mass * s.v[i].x, m.p[1] += mass * s.v[i].y, m.p[2] += mass * s.v[i].z;
    m.magnitude_sum += mass * length(s.v[i]);
  }
  return m;
}

}  // namespace seamless::test
