// Placing spawn entries relative to the scanned scene (`place:` in a spawn entry, docs/PLACEMENT.md):
// on the largest horizontal surface that is not the floor (a desk, a table, a seat), on the floor,
// or on the surface seen at a pixel of a recorded frame. Resolved once the scene exists; the
// resolved position replaces `position` (and is written into the run's effective config).
#pragma once
#include <string>
#include <vector>

#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "io/trajectory.hpp"
#include "physics/solver_params.hpp"
#include "recon/surfaces.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

// What placement can look at: the scan's mesh and horizontal surfaces, its scene particles (to
// refuse a spawn that starts inside geometry) and, for pixel picks, the volume, the tracked
// trajectory (one pose per input frame, in the tracker's world) and the intrinsics.
struct PlacementScene {
  const Mesh* mesh = nullptr;
  std::vector<HorizontalSurface> surfaces;
  const std::vector<vec3>* scene_points = nullptr;
  Volume* volume = nullptr;
  const Trajectory* trajectory = nullptr;
  Intrinsics K{};
  vec3 up{0, 1, 0};
};

// Checks each entry's `place` on its own (PlaceParams::validate: a pixel is two numbers, not given
// together with `on`). A loaded config was checked already (Experiment::validate); this is for
// entries built in code. Throws seamless::Error naming spawn[i].place.
void check_placements(const std::vector<SpawnParams>& spawns);

// One resolved entry, for the log and summary.json.
struct ResolvedPlacement {
  int spawn = 0;
  std::string how;  // "on support 0: 0.61 m^2 at height ...", "pixel (320, 240) of frame 0"
  vec3 surface_point{0, 0, 0};
  vec3 position{0, 0, 0};
};

// Resolves entry i (which has an active place) into its position; throws as resolve_placements.
ResolvedPlacement resolve_placement(int i, SpawnParams& s, const SolverParams& solver, const PlacementScene& scene);

// Resolves every entry with an active place into its position (and leaves the others alone).
// Throws seamless::Error saying what was seen when a placement hits nothing, finds no such surface
// or would start the entry inside the scanned geometry.
std::vector<ResolvedPlacement> resolve_placements(std::vector<SpawnParams>& spawns, const SolverParams& solver,
                                                  const PlacementScene& scene);

// The surfaces' summary for messages: "3 horizontal surfaces: 0.61 m^2 at ...; ...".
std::string describe_surfaces(const std::vector<HorizontalSurface>& surfaces);

}  // namespace seamless::app
