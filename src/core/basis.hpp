// An orthonormal basis around a direction: the one convention the placements (physics' builders,
// recon's surfaces) and the orbit camera share.
#pragma once
#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless {

// Unit vectors t1, t2 spanning the plane normal to the unit vector n, with (t1, t2, n) a
// right-handed orthonormal basis (t1 x t2 = n): t1 = normalize(n x a) for the x axis a, or the y
// axis where n is within 26 degrees of x (so that n x a never nears zero), and t2 = n x t1.
SEAMLESS_HD inline void orthonormal_basis(vec3 n, vec3& t1, vec3& t2) {
  const vec3 a = fabsf(n.x) < 0.9f ? vec3{1.f, 0.f, 0.f} : vec3{0.f, 1.f, 0.f};
  t1 = normalize(cross(n, a));
  t2 = cross(n, t1);
}

}  // namespace seamless
