// The pipeline's stages as the subcommands run them, shared by run, reconstruct and track.
#pragma once
#include <memory>

#include "app/run_context.hpp"
#include "recon/tracker_sequence.hpp"
#include "recon/volume.hpp"
#include "kernels/physics/scene_sdf.hpp"

namespace seamless::app {

struct ScanResult {
  std::unique_ptr<Volume> volume;  // null when tracking only
  TrackSequenceResult tracking;
  Mesh mesh;                       // marching cubes of the volume (empty when tracking only)
};

class RunRenderer;

// Tracks the experiment's input (and fuses it into a new volume when with_volume), writing
// trajectory.txt, tracking_stats.csv and, with a volume, mesh.ply (output.write_mesh).
ScanResult scan(RunContext& ctx, bool with_volume);

// Live mode (dissertation, section 5.2): track, fuse and simulate every frame; the scene particles
// are re-extracted from the volume every experiment.reextract_every fused frames.
void live(RunContext& ctx, RunRenderer* renderer);

// Runs the particle solver for experiment.duration seconds on the given static scene (particles
// and/or an SDF), spawning experiment.spawn, writing particles_<step>.ply every
// output.particles_every steps and the last state as particles.ply.
// A sampled SDF of the scene (x fastest), for solver.scene_collision: sdf.
struct SdfGrid {
  std::vector<float> values;
  int3 dims{0, 0, 0};
  vec3 origin{0, 0, 0};
  float voxel = 0.f;
};

// With a renderer, draws a frame every 1 / (render.fps * solver.dt) steps.
void simulate(RunContext& ctx, const std::vector<vec3>& scene_particles, const kernels::SceneSdf* sdf,
              RunRenderer* renderer = nullptr, const SdfGrid* grid = nullptr);

}  // namespace seamless::app
