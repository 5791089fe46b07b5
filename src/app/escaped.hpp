// Which dynamic particles left the scanned scene at the end of a run (summary.json's `escaped`,
// docs/PLACEMENT.md): a particle that fell through the scan or out of it, told apart from one that
// still moves on or near a surface (a splash). Depends on core only, so that tests link it alone.
#pragma once
#include <cstdint>
#include <optional>

#include "core/math.hpp"
#include "core/mesh.hpp"
#include "core/particles.hpp"

namespace seamless::app {

// A particle counts once, in the first class it falls in:
// - below_floor: more than two diameters under the floor;
// - outside: more than two diameters outside the scanned mesh's bounds;
// - falling: moving down faster than kFallSpeed where no surface will catch it, i.e. either
//   through a surface (more than a diameter below an upward-facing scanned surface directly above
//   it: its whole sphere is past that surface, which did not hold it) or over nothing (no scanned
//   surface under it in its column and no floor plane).
// A particle moving down on or above the surface under it is a splash, not an escape; one at rest
// under an upward-facing surface lies under an overhang (or came through a hole and rests on the
// floor below it, which the final positions cannot tell apart) and is in the scene.
struct EscapedParticles {
  std::int64_t below_floor = 0, outside = 0, falling = 0;
  std::int64_t total() const { return below_floor + outside + falling; }
};
struct SceneBounds {
  vec3 lo{0, 0, 0}, hi{0, 0, 0};  // world bounds of the scanned mesh
  std::optional<float> floor;     // floor height along up, when the floor was seen
  vec3 up{0, 1, 0};
};
// The scanned mesh's bounds and `up`; the floor's height is the caller's (when the floor was seen).
SceneBounds mesh_bounds(const Mesh& mesh, vec3 up, std::optional<float> floor);
constexpr float kFallSpeed = 0.5f;  // m/s: free fall reaches it in 0.05 s (12 mm of drop)
// `mesh` is the scan the bounds came from: its vertices (and normals, where it has them; without
// them every vertex counts as upward-facing) are the surfaces under and over each particle.
EscapedParticles count_escaped(const ParticleState& s, const SceneBounds& b, const Mesh& mesh, float diameter);

}  // namespace seamless::app
