#include "app/escaped.hpp"

#include <cmath>
#include <unordered_map>
#include <vector>

namespace seamless::app {

SceneBounds mesh_bounds(const Mesh& mesh, vec3 up, std::optional<float> floor) {
  SceneBounds b;
  b.up = up;
  b.floor = floor;
  const Box3 bounds = point_bounds(mesh.positions);
  b.lo = bounds.lo, b.hi = bounds.hi;
  return b;
}

namespace {

// A particle moving down fast enough to be falling, and what the scan has in its column.
struct FallingCandidate {
  std::size_t id;
  float height;               // along up
  bool through = false;       // an upward-facing surface directly above it by more than a diameter
  bool over_surface = false;  // a scanned surface in its column no higher than a diameter above its centre
};

}  // namespace

EscapedParticles count_escaped(const ParticleState& s, const SceneBounds& b, const Mesh& mesh, float diameter) {
  EscapedParticles e;
  const float margin = 2.f * diameter;
  const vec3 up = normalize(b.up);
  std::vector<FallingCandidate> falling;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.inv_mass[i] == 0.f) continue;  // pinned cloth corners stay where they were put
    const vec3 x = s.x[i];
    const float h = dot(x, up);
    if (b.floor && h < *b.floor - margin) ++e.below_floor;
    else if (x.x < b.lo.x - margin || x.y < b.lo.y - margin || x.z < b.lo.z - margin || x.x > b.hi.x + margin ||
             x.y > b.hi.y + margin || x.z > b.hi.z + margin)
      ++e.outside;
    else if (-dot(s.v[i], up) > kFallSpeed) falling.push_back({i, h});
  }
  if (falling.empty()) return e;

  // The falling particles by horizontal cell (a diameter wide, in a basis of the plane normal to
  // up), then one pass over the scan's vertices: each looks at the candidates of its 3x3 cells,
  // which hold every candidate within a diameter of it horizontally.
  const vec3 a = std::fabs(up.x) < 0.9f ? vec3{1.f, 0.f, 0.f} : vec3{0.f, 1.f, 0.f};
  const vec3 e1 = normalize(cross(up, a)), e2 = cross(up, e1);
  auto cell = [&](vec3 p) {
    return std::make_pair(static_cast<std::int64_t>(std::floor(dot(p, e1) / diameter)),
                          static_cast<std::int64_t>(std::floor(dot(p, e2) / diameter)));
  };
  auto key = [](std::int64_t u, std::int64_t w) { return (u << 32) ^ (w & 0xffffffff); };
  std::unordered_map<std::int64_t, std::vector<std::size_t>> grid;
  for (std::size_t k = 0; k < falling.size(); ++k) {
    auto [u, w] = cell(s.x[falling[k].id]);
    grid[key(u, w)].push_back(k);
  }
  // Upward-facing: a surface facing more up than sideways, which a particle lies on rather than
  // beside (a wall's vertices next to a particle are not over it).
  const float up_facing = std::sqrt(0.5f);
  const bool normals = mesh.normals.size() == mesh.positions.size();
  for (std::size_t j = 0; j < mesh.positions.size(); ++j) {
    const vec3 p = mesh.positions[j];
    const float hp = dot(p, up);
    const bool facing_up = !normals || dot(mesh.normals[j], up) >= up_facing;
    auto [u, w] = cell(p);
    for (std::int64_t du = -1; du <= 1; ++du)
      for (std::int64_t dw = -1; dw <= 1; ++dw) {
        auto it = grid.find(key(u + du, w + dw));
        if (it == grid.end()) continue;
        for (std::size_t k : it->second) {
          FallingCandidate& c = falling[k];
          const vec3 d = p - s.x[c.id];
          const float dv = hp - c.height;
          const float r2 = std::max(0.f, dot(d, d) - dv * dv);  // squared horizontal distance
          // Directly above: within the particle's radius of its centre line. A surface's marching
          // cubes vertices are at most a voxel apart, so a scan whose voxel is no larger than the
          // radius has a vertex there wherever a surface is.
          if (facing_up && dv > diameter && r2 <= 0.25f * diameter * diameter) c.through = true;
          // Under it or at its height: the surface it splashes on, or will land on.
          if (dv <= diameter && r2 <= diameter * diameter) c.over_surface = true;
        }
      }
  }
  for (const FallingCandidate& c : falling)
    if (c.through || (!c.over_surface && !b.floor)) ++e.falling;
  return e;
}

}  // namespace seamless::app
