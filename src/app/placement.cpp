#include "app/placement.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdio>
#include <unordered_map>

#include "core/error.hpp"
#include "physics/builders.hpp"

namespace seamless::app {
namespace {

std::string entry_name(int i, const SpawnParams& s) { return s.label(i); }

std::string fmt_vec(vec3 v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "(%.3f, %.3f, %.3f)", v.x, v.y, v.z);
  return buf;
}

// The surface point of a pixel pick: a ray from frame `frame`'s tracked camera through the pixel,
// into the model (the volume's raycast, as a person points at a spot in a picture).
vec3 pixel_point(int i, const SpawnParams& s, const PlacementScene& scene) {
  const PlaceParams& pl = s.place;
  const std::string who = entry_name(i, s) + ".place";
  if (!scene.volume || !scene.trajectory) throw Error(who + ": a pixel pick needs the scan's volume and trajectory");
  if (pl.frame >= static_cast<int>(scene.trajectory->size()))
    throw ConfigError(who + ".frame is " + std::to_string(pl.frame) + " but the scan has " +
                      std::to_string(scene.trajectory->size()) + " frames");
  const int u = pl.pixel[0], v = pl.pixel[1];
  if (u >= scene.K.width || v >= scene.K.height)
    throw ConfigError(who + ".pixel (" + std::to_string(u) + ", " + std::to_string(v) + ") is outside the " +
                      std::to_string(scene.K.width) + "x" + std::to_string(scene.K.height) + " image");
  const SE3 pose = (*scene.trajectory)[pl.frame].se3();
  RaycastMaps maps = scene.volume->raycast(scene.K, pose);
  const std::vector<float> depth = maps.depth.to_host();
  const std::vector<vec3> vertex = maps.vertex.to_host();
  const std::size_t at = static_cast<std::size_t>(v) * scene.K.width + u;
  if (!(depth[at] > 0.f)) {
    std::size_t hits = 0;
    for (float d : depth) hits += d > 0.f;
    throw Error(who + ": pixel (" + std::to_string(u) + ", " + std::to_string(v) + ") of frame " +
                std::to_string(pl.frame) + " sees no scanned surface (" + std::to_string(100 * hits / depth.size()) +
                "% of that view does; pick a pixel on the scan)");
  }
  return vertex[at];
}

const HorizontalSurface& surface_pick(int i, const SpawnParams& s, const PlacementScene& scene) {
  const PlaceParams& pl = s.place;
  const std::string who = entry_name(i, s) + ".place";
  if (pl.on == PlaceOn::floor) {
    if (const HorizontalSurface* f = find_floor(scene.surfaces)) return *f;
    throw Error(who + ": on floor, but no floor was seen in the scan; " + describe_surfaces(scene.surfaces));
  }
  const std::vector<const HorizontalSurface*> support = support_surfaces(scene.surfaces);
  if (pl.index < static_cast<int>(support.size())) return *support[pl.index];
  throw Error(who + ": on support, index " + std::to_string(pl.index) + ", but the scan has " +
              std::to_string(support.size()) + " horizontal surface(s) larger than 0.04 m^2 besides the floor; " +
              describe_surfaces(scene.surfaces));
}

// The surface's centre moved by place.offset along world x and z, onto the surface: the nearest of
// its cells (within a cell's diagonal), at that cell's height.
vec3 offset_point(int i, const SpawnParams& s, const HorizontalSurface& f, vec3 up) {
  const vec3 target = f.centre + vec3{s.place.offset[0], 0.f, s.place.offset[1]};
  float best = 1e30f;
  vec3 at = f.centre;
  for (vec3 c : f.cells) {
    const vec3 d = c - target;
    const float across = dot(d, d) - dot(d, up) * dot(d, up);
    if (across < best) best = across, at = c;
  }
  if (std::sqrt(best) > f.cell * std::sqrt(2.f))
    throw Error(entry_name(i, s) + ".place.offset [" + std::to_string(s.place.offset[0]) + ", " +
                std::to_string(s.place.offset[1]) + "] leaves the surface (" + describe(f) + ") by " +
                std::to_string(std::sqrt(best)) + " m: the point " + fmt_vec(target) + " is not on it");
  return at;
}

// How many of the entry's particles would start closer than half a diameter to a scene particle
// (inside the scanned geometry), against how many it has.
std::pair<std::size_t, std::size_t> overlap(const SpawnParams& s, const SolverParams& p,
                                            const std::vector<vec3>& scene) {
  ParticleBatch b;
  if (s.kind == SpawnKind::fluid_block) b = make_fluid_block(s, p);
  else if (s.kind == SpawnKind::cloth) b = make_cloth(s, p);
  else if (s.kind == SpawnKind::rigid) b = make_rigid(s, p);
  else b = make_emitter_layer(s, p);
  const float cell = p.particle_diameter, r = 0.5f * p.particle_diameter;
  auto key = [cell](vec3 x) {
    const auto c = [cell](float v) { return static_cast<std::int64_t>(std::floor(v / cell)) & 0x1fffff; };
    return (c(x.x) << 42) | (c(x.y) << 21) | c(x.z);
  };
  std::unordered_map<std::int64_t, std::vector<vec3>> grid;
  for (vec3 x : scene) grid[key(x)].push_back(x);
  std::size_t inside = 0;
  for (vec3 x : b.x) {
    bool hit = false;
    for (int dx = -1; dx <= 1 && !hit; ++dx)
      for (int dy = -1; dy <= 1 && !hit; ++dy)
        for (int dz = -1; dz <= 1 && !hit; ++dz) {
          auto it = grid.find(key(x + vec3{dx * cell, dy * cell, dz * cell}));
          if (it == grid.end()) continue;
          for (vec3 q : it->second)
            if (length(q - x) < r) {
              hit = true;
              break;
            }
        }
    inside += hit;
  }
  return {inside, b.x.size()};
}

}  // namespace

void check_placements(const std::vector<SpawnParams>& spawns) {
  for (int i = 0; i < static_cast<int>(spawns.size()); ++i)
    spawns[i].place.validate(entry_name(i, spawns[i]) + ".place");
}

std::string describe_surfaces(const std::vector<HorizontalSurface>& surfaces) {
  if (surfaces.empty()) return "the scan has no horizontal surface larger than 0.04 m^2";
  std::string out = "largest horizontal surfaces: ";
  for (std::size_t i = 0; i < surfaces.size() && i < 5; ++i) out += (i ? "; " : "") + describe(surfaces[i]);
  return out;
}

ResolvedPlacement resolve_placement(int i, SpawnParams& s, const SolverParams& solver, const PlacementScene& scene) {
  ResolvedPlacement r;
  r.spawn = i;
  if (!s.place.pixel.empty()) {
    r.surface_point = pixel_point(i, s, scene);
    r.how = "pixel (" + std::to_string(s.place.pixel[0]) + ", " + std::to_string(s.place.pixel[1]) + ") of frame " +
            std::to_string(s.place.frame);
  } else {
    const HorizontalSurface& f = surface_pick(i, s, scene);
    r.surface_point = s.place.offset.empty() ? f.centre : offset_point(i, s, f, scene.up);
    r.how = std::string("on ") + enum_name(s.place.on);
    if (s.place.on == PlaceOn::support) r.how.append(" ").append(std::to_string(s.place.index));
    r.how += ": " + describe(f);
  }
  r.position = r.surface_point + normalize(scene.up) * s.place.above;
  s.position = r.position;
  if (scene.scene_points && !scene.scene_points->empty()) {
    const auto [inside, total] = overlap(s, solver, *scene.scene_points);
    // A few particles of a sheet or block may graze the scan's noisy surface (each one is pushed
    // out by its contact); a tenth inside means the entry starts in a wall or under the surface.
    if (inside * 10 > total)
      throw Error(entry_name(i, s) + ".place (" + r.how + ", " + std::to_string(s.place.above) + " m above) puts " +
                  std::to_string(inside) + " of its " + std::to_string(total) +
                  " particles inside the scanned geometry at " + fmt_vec(r.position) + ": raise `above`");
  }
  spdlog::info("place: {} at {} ({}, {:.2f} m above {})", entry_name(i, s), fmt_vec(r.position), r.how, s.place.above,
               fmt_vec(r.surface_point));
  return r;
}

std::vector<ResolvedPlacement> resolve_placements(std::vector<SpawnParams>& spawns, const SolverParams& solver,
                                                  const PlacementScene& scene) {
  check_placements(spawns);
  std::vector<ResolvedPlacement> out;
  for (int i = 0; i < static_cast<int>(spawns.size()); ++i)
    if (spawns[i].place.active()) out.push_back(resolve_placement(i, spawns[i], solver, scene));
  return out;
}

}  // namespace seamless::app
