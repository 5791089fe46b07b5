// Solver section (`solver:`) and spawn entries (`spawn:`): the unified particle solver of
// Macklin, Mueller, Chentanez and Kim 2014, with Position Based Fluids (Macklin & Mueller 2013)
// and Akinci 2013 cohesion / surface tension.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

struct SolverParams {
  float particle_diameter = 0.04f;      // metres; one radius for every particle (Macklin 2014)
  float dt = 0.01f;                     // seconds per frame step
  int iterations = 2;                   // constraint (Jacobi) iterations per substep
  int substeps = 1;
  vec3 gravity{0.f, -9.81f, 0.f};       // world frame, m/s^2
  std::int64_t max_particles = 1 << 20;
  float static_friction = 0.5f;
  float kinetic_friction = 0.3f;
  float restitution = 0.f;
  float rest_density = 1000.f;          // kg/m^3 (water)
  float viscosity = 0.01f;              // XSPH coefficient c (Macklin & Mueller 2013, eq. 17)
  float vorticity = 0.0001f;            // vorticity confinement epsilon (ibid., eq. 16)
  float cohesion = 0.01f;               // Akinci 2013 cohesion gamma
  float surface_tension = 0.01f;        // Akinci 2013 curvature term
  std::string scene_collision = "particles";
  float sleep_threshold = 0.f;          // m/s; 0 = never sleep
  float max_speed = 20.f;               // m/s, clamps blow-ups
  int max_neighbours = 64;

  template <class V> void visit(V& v) {
    v("particle_diameter", particle_diameter, "particle diameter, metres", Range{0.001, 1.0});
    v("dt", dt, "time step per simulated frame, seconds", Range{1e-5, 1.0});
    v("iterations", iterations, "constraint iterations per substep", Range{1, 1000});
    v("substeps", substeps, "substeps per time step", Range{1, 1000});
    v("gravity", gravity, "gravity in world coordinates, m/s^2");
    v("max_particles", max_particles, "particle capacity", Range{1, 1e9});
    v("static_friction", static_friction, "static friction coefficient", Range{0.0, 10.0});
    v("kinetic_friction", kinetic_friction, "kinetic friction coefficient", Range{0.0, 10.0});
    v("restitution", restitution, "coefficient of restitution", Range{0.0, 1.0});
    v("rest_density", rest_density, "fluid rest density, kg/m^3", Range{1.0, 1e5});
    v("viscosity", viscosity, "XSPH viscosity coefficient", Range{0.0, 1.0});
    v("vorticity", vorticity, "vorticity confinement strength", Range{0.0, 10.0});
    v("cohesion", cohesion, "fluid cohesion strength (Akinci 2013)", Range{0.0, 100.0});
    v("surface_tension", surface_tension, "fluid surface tension strength (Akinci 2013)", Range{0.0, 100.0});
    v("scene_collision", scene_collision, "collide against static scene particles or the sampled TSDF",
      Choices{"particles", "sdf"});
    v("sleep_threshold", sleep_threshold, "particles slower than this are frozen, m/s; 0 = off", Range{0.0, 100.0});
    v("max_speed", max_speed, "speed clamp, m/s", Range{0.0, 1e4});
    v("max_neighbours", max_neighbours, "neighbours kept per particle", Range{1, 1024});
  }
};

// One thing to drop into the scene at time `time`. Which fields matter depends on `kind`.
struct SpawnParams {
  std::string kind = "fluid_block";
  float time = 0.f;                   // seconds of simulated time
  vec3 position{0.f, 1.f, 0.f};       // world, metres (centre; emitter: nozzle)
  vec3 size{0.2f, 0.2f, 0.2f};        // metres (fluid_block, rigid box/sphere bounding box)
  vec3 velocity{0.f, 0.f, 0.f};       // m/s (initial velocity; emitter: jet velocity)
  float rate = 500.f;                 // emitter: particles per second
  float duration = 0.f;               // emitter: seconds to run; 0 = until the end
  float nozzle_radius = 0.05f;        // emitter, metres
  int nx = 32, ny = 32;               // cloth grid
  float spacing = 0.f;                // cloth particle spacing, metres; 0 = particle diameter
  std::vector<int> pinned;            // cloth corners held fixed: 0..3 = (0,0) (nx-1,0) (0,ny-1) (nx-1,ny-1)
  float stiffness = 1.f;              // cloth stretch stiffness (PBD k)
  std::string shape = "box";          // rigid
  std::string mesh;                   // rigid, shape: mesh (OBJ/PLY path)

  template <class V> void visit(V& v) {
    v("kind", kind, "what to spawn", Choices{"fluid_block", "emitter", "cloth", "rigid"});
    v("time", time, "when to spawn, seconds of simulated time", Range{0.0, 1e6});
    v("position", position, "centre (emitter: nozzle position), world metres");
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
    v("shape", shape, "rigid body shape", Choices{"box", "sphere", "mesh"});
    v("mesh", mesh, "rigid body mesh file (shape: mesh)");
  }
};

}  // namespace seamless
