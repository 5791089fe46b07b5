// Horizontal surfaces of a reconstruction (the floor, desks, tables, seats), found with gravity:
// where spawn entries can be placed (`place: {on: support}`, docs/PLACEMENT.md) and where the
// floor plane under unseen floor goes.
#pragma once
#include <string>
#include <vector>

#include "core/math.hpp"
#include "recon/volume.hpp"

namespace seamless {

struct HorizontalSurface {
  float height = 0.f;             // metres along `up` (area-weighted mean of its pieces)
  float area = 0.f;               // m^2 of upward-facing surface
  vec3 centre{0, 0, 0};           // the surface's most open point (see find_horizontal_surfaces), world
  float open_radius = 0.f;        // metres of free surface around the centre (at most SurfaceParams::open_radius)
  vec3 lo{0, 0, 0}, hi{0, 0, 0};  // world bounds of its pieces
  bool floor = false;
  std::vector<vec3> cells;  // the mean point of each of its grid cells (where it can be stood on)
  float cell = 0.f;         // their size across the surface, metres
};

struct SurfaceParams {
  float cell = 0.05f;         // grid cell across the surface, metres
  float height_bin = 0.03f;   // height quantum; pieces one bin apart join (scan noise at 2-4 m)
  float max_tilt_deg = 15.f;  // a piece whose normal is further than this from up is not horizontal
  float min_area = 0.04f;     // m^2: smaller components are clutter (a book, a cup's rim)
  float clearance = 0.4f;     // metres above the surface within which anything scanned is an obstacle
  float open_radius = 0.3f;   // the centre is chosen among cells this open (free surface around them)
  // The floor: the lowest surface of at least floor_min_area that lies floor_min_drop below the
  // mean camera (a room scanned from eye height), or half that with another surface at least
  // furniture_rise above it (a seat or desk stands on it; things on a desk are lower).
  float floor_min_area = 0.2f;
  float floor_min_drop = 1.0f;
  float furniture_rise = 0.35f;
};

// Upward-facing surfaces of `mesh` (world coordinates, `up` = -gravity, unit), largest first.
// Triangles within max_tilt_deg of horizontal are binned into cells of (cell x cell x height_bin)
// and joined to their 26 neighbours; each component is one surface. camera_positions (the
// trajectory's, may be empty) decide which surface is the floor.
std::vector<HorizontalSurface> find_horizontal_surfaces(const Mesh& mesh, vec3 up,
                                                        const std::vector<vec3>& camera_positions,
                                                        const SurfaceParams& p = {});

// The floor, or null when none was seen.
const HorizontalSurface* find_floor(const std::vector<HorizontalSurface>& surfaces);
// Support surfaces (not the floor), largest first.
std::vector<const HorizontalSurface*> support_surfaces(const std::vector<HorizontalSurface>& surfaces);

// "area 0.61 m^2 at height -0.72 m, centre (x, y, z)" for messages and logs.
std::string describe(const HorizontalSurface& s);

}  // namespace seamless
