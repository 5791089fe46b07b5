// Solver section (`solver:`) and spawn entries (`spawn:`): the unified particle solver of
// Macklin, Mueller, Chentanez and Kim 2014, with Position Based Fluids (Macklin & Mueller 2013)
// and Akinci 2013 cohesion / surface tension.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

enum class SpawnKind { fluid_block, emitter, cloth, rigid };
inline std::span<const EnumName<SpawnKind>> enum_names(SpawnKind) {
  static constexpr EnumName<SpawnKind> names[] = {{SpawnKind::fluid_block, "fluid_block"},
                                                  {SpawnKind::emitter, "emitter"},
                                                  {SpawnKind::cloth, "cloth"},
                                                  {SpawnKind::rigid, "rigid"}};
  return names;
}
enum class RigidShape { box, sphere, mesh };
inline std::span<const EnumName<RigidShape>> enum_names(RigidShape) {
  static constexpr EnumName<RigidShape> names[] = {
      {RigidShape::box, "box"}, {RigidShape::sphere, "sphere"}, {RigidShape::mesh, "mesh"}};
  return names;
}
enum class PlaceOn { none, support, floor };
inline std::span<const EnumName<PlaceOn>> enum_names(PlaceOn) {
  static constexpr EnumName<PlaceOn> names[] = {
      {PlaceOn::none, "none"}, {PlaceOn::support, "support"}, {PlaceOn::floor, "floor"}};
  return names;
}
enum class SceneCollision { particles, sdf };
inline std::span<const EnumName<SceneCollision>> enum_names(SceneCollision) {
  static constexpr EnumName<SceneCollision> names[] = {{SceneCollision::particles, "particles"},
                                                       {SceneCollision::sdf, "sdf"}};
  return names;
}
enum class DynamicColliders { none, depth, all };
inline std::span<const EnumName<DynamicColliders>> enum_names(DynamicColliders) {
  static constexpr EnumName<DynamicColliders> names[] = {
      {DynamicColliders::none, "none"}, {DynamicColliders::depth, "depth"}, {DynamicColliders::all, "all"}};
  return names;
}

struct SolverParams {
  float particle_diameter = 0.04f;  // metres; one radius for every particle (Macklin 2014)
  float dt = 0.01f;                 // seconds per frame step
  int iterations = 2;               // constraint (Jacobi) iterations per substep
  int substeps = 1;
  vec3 gravity{0.f, -9.81f, 0.f};  // world frame, m/s^2
  // Against gravity, unit length (+y without gravity): what lies flat, stands and rests.
  vec3 up() const {
    const float l = length(gravity);
    return l > 0.f ? gravity * (-1.f / l) : vec3{0.f, 1.f, 0.f};
  }
  std::int64_t max_particles = 1 << 20;
  float static_friction = 0.5f;
  float kinetic_friction = 0.3f;
  float restitution = 0.f;
  float fluid_friction = 0.f;     // fluid on the scene and on solids; 0: fluids slip (Macklin 2014)
  float rest_density = 1000.f;    // kg/m^3 (water)
  float viscosity = 0.01f;        // XSPH coefficient c (Macklin & Mueller 2013, eq. 17)
  float vorticity = 0.0001f;      // vorticity confinement epsilon (ibid., eq. 16)
  float cohesion = 0.01f;         // Akinci 2013 cohesion gamma
  float surface_tension = 0.01f;  // Akinci 2013 curvature term
  SceneCollision scene_collision = SceneCollision::particles;
  float sleep_threshold = 0.f;  // m/s; 0 = never sleep
  float max_speed = 4.f;        // m/s: speed limit; sets the substeps (docs/PHYSICS.md)
  int max_neighbours = 64;
  // Solver details (docs/PHYSICS.md).
  int stabilization_iterations = 1;  // Macklin 2014 section 4.4 pre-stabilisation passes
  float relaxation = 1.f;            // SOR factor omega of averaged contacts (Macklin 2014 eq. 11)
  float tunnel_fraction = 0.5f;      // substeps keep max_speed * dt_sub <= this * diameter
  float fluid_smoothing = 2.f;       // PBF smoothing radius h in particle diameters
  float fluid_relaxation = 0.01f;    // PBF epsilon as a fraction of the rest lattice's sum |grad C|^2
  bool fluid_unilateral = true;      // density constraint only pushes apart (Macklin 2014 7.1)
  float tensile_k = 0.f;             // PBF s_corr k (eq. 13); 0 = off
  float tensile_dq = 0.2f;           // PBF s_corr delta q in units of h
  float solid_density_scale = 1.f;   // weight of solid neighbours in fluid density
  float drag = 0.f;                  // cloth drag coefficient C_D (Keckeisen 2004)
  float lift = 0.f;                  // cloth lift coefficient C_L
  float air_density = 1.2f;          // kg/m^3
  vec3 wind{0.f, 0.f, 0.f};          // m/s
  float cloth_relaxation = 2.f;      // cloth constraint averaging: k / max(1, degree / this)
  int rotation_iterations = 8;       // Mueller 2016 rotation extraction steps per shape match
  int max_static_neighbours = 64;
  int cloth_strain_passes = 4;               // strain-limiting passes over all edge colours per substep
  float cloth_strain_omega = 1.5f;           // over-relaxation of strain limiting
  float cloth_strain_contact_weight = 0.3f;  // strain limiting: inverse-mass factor of particles on the scene
  bool cuda_graph = true;                    // CUDA: replay a step as one captured graph (docs/PHYSICS.md)
  // Live colliders: the depth camera's points as kinematic colliders each frame (people and moving
  // objects push the simulation): none, the dynamic pixels only (dynamic.enabled), or every pixel.
  DynamicColliders dynamic_colliders = DynamicColliders::none;
  int collider_level = 2;           // pyramid level whose vertex map gives the points (2: 160x120)
  float collider_thickness = 0.1f;  // metres of colliders behind each seen surface point, along its ray

  // |gravity| above this is refused (docs/CONFIG.md): ten times Earth's, four times Jupiter's
  // surface gravity. At the default step (0.01 s) a particle then falls g dt^2 = 1 cm per step, a
  // quarter of the default diameter; far beyond it particles pass through a particle-thin scene.
  static constexpr float kMaxGravity = 100.f;  // m/s^2
  // Rules across keys and physical sanity, checked when a config is loaded (Experiment::validate).
  void check(std::vector<std::string>& problems) const {
    const double x = gravity.x, y = gravity.y, z = gravity.z;  // in double: 1e30 squared overflows a float
    const double g = std::sqrt(x * x + y * y + z * z);
    if (!(g <= kMaxGravity)) {
      char got[128];
      std::snprintf(got, sizeof got, "[%g, %g, %g] (|g| = %g m/s^2)", gravity.x, gravity.y, gravity.z, g);
      problems.push_back(std::string("solver.gravity: ") + got + " is beyond the sanity bound of " +
                         std::to_string(static_cast<int>(kMaxGravity)) +
                         " m/s^2 (Earth: 9.81); give it in m/s^2, e.g. [0, -9.81, 0]");
    }
  }

  template <class V> void visit(V& v) {
    v("particle_diameter", particle_diameter, "particle diameter, metres", Range{0.001, 1.0});
    v("dt", dt, "time step per simulated frame, seconds", Range{1e-5, 1.0});
    v("iterations", iterations, "constraint iterations per substep", Range{1, 1000});
    v("substeps", substeps, "minimum substeps per time step (more if max_speed needs them)", Range{1, 1000});
    v("gravity", gravity, "gravity in world coordinates, m/s^2");
    v("max_particles", max_particles, "particle capacity", Range{1, 1e9});
    v("static_friction", static_friction, "static friction coefficient", Range{0.0, 10.0});
    v("kinetic_friction", kinetic_friction, "kinetic friction coefficient", Range{0.0, 10.0});
    v("restitution", restitution, "coefficient of restitution", Range{0.0, 1.0});
    v("fluid_friction", fluid_friction,
      "friction coefficient of fluid on the scene and on solids (static and kinetic); 0: fluids slip. Real "
      "water wets what it runs over: without it a film spreads without end over an unbounded floor",
      Range{0.0, 10.0});
    v("rest_density", rest_density, "fluid rest density, kg/m^3", Range{1.0, 1e5});
    v("viscosity", viscosity, "XSPH viscosity coefficient", Range{0.0, 1.0});
    v("vorticity", vorticity, "vorticity confinement strength", Range{0.0, 10.0});
    v("cohesion", cohesion, "fluid cohesion strength (Akinci 2013)", Range{0.0, 100.0});
    v("surface_tension", surface_tension, "fluid surface tension strength (Akinci 2013)", Range{0.0, 100.0});
    v("scene_collision", scene_collision, "collide against static scene particles or the sampled TSDF");
    v("sleep_threshold", sleep_threshold, "particles slower than this are frozen, m/s; 0 = off", Range{0.0, 100.0});
    v("max_speed", max_speed, "speed limit, m/s; sets the substeps so that nothing tunnels", Range{0.01, 1e4});
    v("max_neighbours", max_neighbours, "neighbours kept per particle", Range{1, 1024});
    v("stabilization_iterations", stabilization_iterations, "pre-stabilisation passes on initial contacts",
      Range{0, 100});
    v("relaxation", relaxation, "SOR factor of averaged contact corrections", Range{0.1, 2.0});
    v("tunnel_fraction", tunnel_fraction, "max distance per substep at max_speed, in diameters", Range{0.05, 1.0});
    v("fluid_smoothing", fluid_smoothing, "fluid smoothing radius h, in particle diameters", Range{1.0, 4.0});
    v("fluid_relaxation", fluid_relaxation, "PBF constraint relaxation epsilon (relative)", Range{0.0, 100.0});
    v("fluid_unilateral", fluid_unilateral, "fluid density constraint only pushes particles apart");
    v("tensile_k", tensile_k, "PBF artificial pressure k; 0 = off", Range{0.0, 1.0});
    v("tensile_dq", tensile_dq, "PBF artificial pressure delta q, in units of h", Range{0.0, 1.0});
    v("solid_density_scale", solid_density_scale, "weight of solid neighbours in fluid density", Range{0.0, 10.0});
    v("drag", drag, "cloth aerodynamic drag coefficient", Range{0.0, 100.0});
    v("lift", lift, "cloth aerodynamic lift coefficient", Range{0.0, 100.0});
    v("air_density", air_density, "air density, kg/m^3", Range{0.0, 100.0});
    v("wind", wind, "wind velocity, m/s");
    v("cloth_relaxation", cloth_relaxation, "cloth constraint averaging divisor", Range{0.5, 16.0});
    v("rotation_iterations", rotation_iterations, "rotation extraction iterations", Range{1, 100});
    v("max_static_neighbours", max_static_neighbours, "scene particles kept per particle", Range{1, 1024});
    v("cloth_strain_passes", cloth_strain_passes, "cloth strain-limiting passes per substep (Provot 1995)",
      Range{0, 100});
    v("cloth_strain_omega", cloth_strain_omega, "over-relaxation of cloth strain limiting", Range{1.0, 1.95});
    v("cloth_strain_contact_weight", cloth_strain_contact_weight,
      "strain limiting: inverse-mass factor of cloth particles touching the scene (1 = none)", Range{0.01, 1.0});
    v("cuda_graph", cuda_graph, "CUDA: capture a step as a graph and replay it while the scene is unchanged");
    v("dynamic_colliders", dynamic_colliders,
      "live mode: each frame's depth points become kinematic collider particles: none, the dynamic pixels only "
      "(depth; needs dynamic.enabled) or every pixel (all)");
    v("collider_level", collider_level,
      "dynamic_colliders: the depth pyramid level whose points are used (0 = full resolution; each level halves "
      "both sides)",
      Range{0, 3});
    v("collider_thickness", collider_thickness,
      "dynamic_colliders: metres of collider particles behind each seen point along its camera ray (the camera "
      "sees only the front of a person; particles pushed past that shell would be inside them)",
      Range{0.0, 2.0});
  }
};

// Where a spawn entry goes relative to the scanned scene, resolved once the scene exists (after the
// scan, or in live mode once the surface is there): on a horizontal surface found with gravity, or
// on the surface seen at a pixel of a recorded frame. `on: none` and no pixel: `position` is used
// as given (world metres). docs/PLACEMENT.md.
struct PlaceParams {
  PlaceOn on = PlaceOn::none;  // support: the index-th largest horizontal surface that is not the floor
  int index = 0;               // 0 = largest
  float above = 0.15f;         // metres above the surface (to the entry's centre)
  std::vector<float> offset;   // [x, z]: metres from the surface's centre along world x and z
  std::vector<int> pixel;      // [u, v]: the surface seen at this pixel of frame `frame`
  int frame = 0;               // input frame whose camera the pixel belongs to

  bool active() const { return on != PlaceOn::none || !pixel.empty(); }
  // Rules across keys; `who` names the entry in messages ("spawn[0] (rigid).place"). Checked when a
  // config is loaded (Experiment::validate) and before placing (app/placement.cpp, for code that
  // builds spawn entries without a config).
  void validate(const std::string& who) const {
    std::vector<std::string> problems;
    check(who, problems);
    if (!problems.empty()) throw ConfigError(problems.front());
  }
  // The same, every problem appended to `problems` (config loading lists them all at once).
  void check(const std::string& who, std::vector<std::string>& problems) const {
    if (!pixel.empty() && pixel.size() != 2)
      problems.push_back(who + ".pixel: expected [u, v] (two numbers), got " + std::to_string(pixel.size()));
    if (!pixel.empty() && on != PlaceOn::none)
      problems.push_back(who + ": give either `on` (" + enum_name(on) + ") or `pixel`, not both");
    if (!offset.empty() && offset.size() != 2)
      problems.push_back(who + ".offset: expected [x, z] (two numbers), got " + std::to_string(offset.size()));
    if (!offset.empty() && on == PlaceOn::none)
      problems.push_back(who +
                         ".offset moves an `on:` placement across its surface; it needs `on: support` or `on: floor`");
  }
  template <class V> void visit(V& v) {
    v("on", on, "place on a scanned horizontal surface: support (largest that is not the floor), floor, or none");
    v("index", index, "which surface: 0 = largest, 1 = second largest, ...", Range{0, 1000});
    v("above", above, "height of the entry's centre above the surface, metres", Range{-10.0, 10.0});
    v("offset", offset,
      "[x, z]: metres from the surface's centre along world x (left of the first camera) and z "
      "(ahead of it); the point must lie on the surface",
      Range{-100.0, 100.0});
    v("pixel", pixel, "[u, v]: place on the surface seen at this pixel of input frame `frame`", Range{0, 1e5});
    v("frame", frame, "input frame (0 = first) of the pixel pick", Range{0, 1e9});
  }
};

// One thing to drop into the scene at time `time`. Which fields matter depends on `kind`.
struct SpawnParams {
  SpawnKind kind = SpawnKind::fluid_block;
  float time = 0.f;                    // seconds of simulated time
  vec3 position{0.f, 1.f, 0.f};        // world, metres (centre; emitter: nozzle)
  PlaceParams place;                   // relative to the scan instead (resolved into position)
  vec3 size{0.2f, 0.2f, 0.2f};         // metres (fluid_block, rigid box/sphere bounding box)
  vec3 velocity{0.f, 0.f, 0.f};        // m/s (initial velocity; emitter: jet velocity)
  float rate = 500.f;                  // emitter: particles per second
  float duration = 0.f;                // emitter: seconds to run; 0 = until the end
  float nozzle_radius = 0.05f;         // emitter, metres
  int nx = 32, ny = 32;                // cloth grid
  float spacing = 0.f;                 // cloth particle spacing, metres; 0 = particle diameter
  std::vector<int> pinned;             // cloth corners held fixed: 0..3 = (0,0) (nx-1,0) (0,ny-1) (nx-1,ny-1)
  float stiffness = 1.f;               // cloth stretch stiffness (PBD k); rigid: shape matching stiffness
  float bend_stiffness = 0.1f;         // cloth bending stiffness
  float max_strain = 0.1f;             // cloth: largest relative edge length change (Provot 1995); 0 = no limit
  bool self_collide = false;           // cloth collides with itself
  RigidShape shape = RigidShape::box;  // rigid
  std::string mesh;                    // rigid, shape: mesh (OBJ/PLY path)
  vec3 rotation{0.f, 0.f, 0.f};        // pose: Euler angles about x, y, z (applied in that order), degrees
  float density = 1000.f;              // kg/m^3: particle mass = density * diameter^3 (fluid: solver.rest_density)

  // "spawn[2] (rigid)": how messages name the entry at `index` of the spawn list.
  std::string label(int index) const { return "spawn[" + std::to_string(index) + "] (" + enum_name(kind) + ")"; }
  // Rules across keys, checked when a config is loaded (Experiment::validate). The builders check
  // the mesh path again (physics/builders.cpp) for code that builds entries without a config.
  void check(int index, std::vector<std::string>& problems) const {
    place.check(label(index) + ".place", problems);
    const std::string key = "spawn." + std::to_string(index);
    if (kind == SpawnKind::rigid && shape == RigidShape::mesh && mesh.empty())
      problems.push_back(label(index) + ": " + key + ".shape: mesh needs the key " + key + ".mesh (an OBJ file path)");
    // A block or body of no extent (or a negative one) holds no particle: say so now, not after the scan.
    if ((kind == SpawnKind::fluid_block || kind == SpawnKind::rigid) && !(size.x > 0 && size.y > 0 && size.z > 0)) {
      char got[96];
      std::snprintf(got, sizeof got, "[%g, %g, %g]", size.x, size.y, size.z);
      problems.push_back(label(index) + ": " + key + ".size: every extent must be positive (metres), got " + got);
    }
  }

  template <class V> void visit(V& v) {
    v("kind", kind, "what to spawn");
    v("time", time, "when to spawn, seconds of simulated time", Range{0.0, 1e6});
    v("position", position, "centre (emitter: nozzle position), world metres");
    v("place", place, "place relative to the scanned scene instead of `position` (resolved after the scan)");
    v("size", size, "extent, metres (fluid_block, rigid)");
    v("velocity", velocity, "initial velocity, m/s (emitter: jet velocity)");
    v("rate", rate, "emitter particles per second", Range{0.0, 1e8});
    v("duration", duration, "emitter run time, seconds; 0 = until the end", Range{0.0, 1e6});
    v("nozzle_radius", nozzle_radius, "emitter nozzle radius, metres", Range{0.0, 10.0});
    v("nx", nx, "cloth particles along x", Range{2, 4096});
    v("ny", ny, "cloth particles along y", Range{2, 4096});
    v("spacing", spacing, "cloth particle spacing, metres; 0 = particle diameter", Range{0.0, 10.0});
    v("pinned", pinned, "cloth corners held fixed (0..3)", Range{0, 3});
    v("stiffness", stiffness, "cloth stretch stiffness", Range{0.0, 1.0});
    v("bend_stiffness", bend_stiffness, "cloth bending stiffness", Range{0.0, 1.0});
    v("max_strain", max_strain, "cloth strain limit: largest relative edge stretch or compression; 0 = none",
      Range{0.0, 1.0});
    v("self_collide", self_collide, "cloth collides with itself");
    v("shape", shape, "rigid body shape");
    v("rotation", rotation, "Euler angles about x, y, z, degrees (cloth, rigid)");
    v("density", density, "material density, kg/m^3 (rigid, cloth)", Range{1.0, 1e5});
    v("mesh", mesh, "rigid body mesh file (shape: mesh)");
  }
};

}  // namespace seamless
