#include "core/mesh.hpp"

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

Box3 point_bounds(const std::vector<vec3>& points) {
  Box3 b;
  if (points.empty()) return b;
  b.lo = b.hi = points[0];
  for (const vec3& p : points) b.lo = vmin(b.lo, p), b.hi = vmax(b.hi, p);
  return b;
}

}  // namespace seamless
