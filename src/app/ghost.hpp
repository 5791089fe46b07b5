// The ghost measure of dynamic scenes (summary.json `dynamic.ghost_vertices`): how much of the synthetic
// room's movers stays in the map after they have gone. Needs the movers' exact geometry, so it
// exists only for `input.source: synthetic` with `input.synthetic.movers`.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/mesh.hpp"
#include "io/input_params.hpp"
#include "io/trajectory.hpp"

namespace seamless {

struct GhostCount {
  std::int64_t total = 0;
  std::vector<std::int64_t> by_mover;  // index: mover id - 1 (input.synthetic.movers' order)
};

// Mesh vertices (world frame of the run) inside any mover's capsules at any of the ground truth's
// timestamps by more than `margin`, that do not lie within `margin` of the room's own surface (the
// floor a person's feet stand on, a wall an arm reaches into); each counts for the mover of the
// nearest capsule at the first timestamp it is inside one. The mesh is taken to the room frame
// of groundtruth.txt by the first pose: world_T_room = estimate(t0) * groundtruth(t0)^-1 at the
// first timestamp both have. None without movers or without a common timestamp.
std::optional<GhostCount> ghost_vertices(const Mesh& mesh, const InputParams& in, const Trajectory& estimate,
                                         const Trajectory& groundtruth, float margin);

}  // namespace seamless
