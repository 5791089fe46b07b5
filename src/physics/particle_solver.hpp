// The unified particle solver (Macklin, Mueller, Chentanez, Kim 2014) as the host sees it: one
// object that owns the particle state on one device and steps it with the kernels of
// kernels/physics/solver.hpp, without host round trips inside a step (docs/PHYSICS.md).
//
//   ParticleSolver s(params, Device::CUDA);
//   s.add_static_particles(scene_points);      // and/or s.set_scene_sdf(...)
//   s.schedule(experiment.spawn);              // spawned when their time comes
//   for (...) { s.step(); write_particles_ply(path, s.download_state()); }
//   write_objects(path, s.objects());          // which particles are which body and sheet
//
// The solver owns its object model: each rigid body and cloth sheet it created (spawn entry,
// particle range, rest offsets, body mesh: objects()), each body's frame from its own shape
// matching (rigid_frames()) and the schedule of what spawns when (schedule(), SpawnSchedule).
#pragma once
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/particles.hpp"
#include "core/math.hpp"
#include "kernels/physics/scene_sdf.hpp"
#include "physics/builders.hpp"
#include "physics/objects.hpp"
#include "physics/solver_params.hpp"

namespace seamless {

struct SolverStats {
  std::int64_t particles = 0, fluid_particles = 0, cloth_particles = 0, rigid_particles = 0;
  std::int64_t rigid_bodies = 0, static_particles = 0;
  std::int64_t collider_particles = 0;  // this frame's kinematic colliders (set_collider_particles)
  int substeps = 1;
  double time = 0.0;  // simulated seconds
  std::int64_t steps = 0;
  // Neighbour lists over the cap (particles, summed over substeps since the start): each such
  // particle lost neighbours. Raise solver.max_neighbours if these are not zero.
  std::int64_t neighbour_overflow = 0, static_neighbour_overflow = 0;
  int max_neighbours_seen = 0, max_static_neighbours_seen = 0;
  std::int64_t emitter_dropped = 0;  // particles an emitter could not create (capacity)
  float max_speed = 0.f;             // m/s, after the last step (0 before the first)
};

class ParticleSolver {
 public:
  ParticleSolver(const SolverParams& params, Device device);
  ~ParticleSolver();
  ParticleSolver(const ParticleSolver&) = delete;
  ParticleSolver& operator=(const ParticleSolver&) = delete;

  // Static scene particles (appended to those already there, in order); they never move.
  void add_static_particles(const std::vector<vec3>& points);
  // The same from the first `count` points of a buffer on any device (the scene particles that
  // Volume::extract_scene_particles leaves on the volume's device), copied device to device.
  void add_static_particles(const Buffer<vec3>& points, std::int64_t count);
  void clear_static_particles();
  // This frame's kinematic colliders (solver.dynamic_colliders: points from the depth camera,
  // physics/depth_colliders.hpp), replacing the last frame's: they collide as scene particles do,
  // infinitely heavy, so whatever they move into is pushed out of them.
  void set_collider_particles(const std::vector<vec3>& points);
  // The same from the first `count` points of a buffer on any device, copied device to device.
  void set_collider_particles(const Buffer<vec3>& points, std::int64_t count);
  // Collide against an SDF as well (analytic primitives and/or the synthetic room).
  void set_scene_sdf(const kernels::SceneSdf& sdf);
  // Collide against a dense sampled SDF (x fastest), e.g. resampled from the TSDF.
  void set_scene_sdf_grid(const std::vector<float>& values, int3 dims, vec3 origin, float voxel);

  // Creates the entry's particles now (an emitter starts emitting now), as an object of no spawn
  // index (RigidBody::spawn -1). Returns the first id.
  std::int64_t spawn(const SpawnParams& s);
  // Entries are spawned at the start of each step by SpawnSchedule's rule, their objects carrying
  // their index in `spawns` (counted over every call). Checks the capacity of the whole list first
  // (seamless::Error naming the entry).
  void schedule(const std::vector<SpawnParams>& spawns);
  // A gate that may hold a due entry back until a later step (SpawnSchedule::Gate; live mode).
  void set_spawn_gate(SpawnSchedule::Gate gate);
  // The scheduled entry with the earliest time, spawned now (the window's key G); says so in the
  // log, or that every entry is spawned already.
  void spawn_next();
  // Scheduled entries not spawned yet.
  std::size_t pending_spawns() const;
  // Adds a prepared batch (builders.hpp); returns the first id.
  std::int64_t add_batch(const ParticleBatch& b);

  // Advances by dt (default: params.dt) in substeps() substeps.
  void step(float dt = -1.f);
  // Substeps per step: the most of params.substeps and ceil(max_speed * dt / (tunnel_fraction *
  // diameter)), so that no particle moves further than tunnel_fraction diameters in a substep.
  int substeps(float dt = -1.f) const;

  SolverStats stats() const;
  ParticleState download_state() const;
  // Each rigid body's frame now, from the solver's own shape matching (in objects().bodies order).
  std::vector<RigidFrame> rigid_frames() const;
  // The rigid bodies and cloth sheets created so far (read-only; valid until the next spawn).
  const SceneObjects& objects() const;
  // Positions and phases of the size() particles in id order on device(), read-only, valid until
  // the next step or spawn (for CUDA-OpenGL interop: the renderer copies them device to device).
  // The solver keeps its state in sorted order; the first call after a step copies it into id
  // order (one kernel, on the default stream).
  const vec3* device_positions() const;
  const std::uint32_t* device_phases() const;
  std::int64_t size() const;
  const SolverParams& params() const;
  Device device() const;
  // Rest number density rho_0 of the fluid (kernel sum of the rest lattice), 1/m^3.
  float fluid_rest_density() const;
  // Fluid density / rest density of each particle (id order) at the positions now.
  std::vector<float> fluid_density_ratio() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace seamless
