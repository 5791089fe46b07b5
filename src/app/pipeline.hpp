// The pipeline's stages as the subcommands run them, shared by run, reconstruct and track.
#pragma once
#include <memory>
#include <optional>

#include "app/ghost.hpp"
#include "app/run_context.hpp"
#include "io/frame_source.hpp"
#include "kernels/physics/scene_sdf.hpp"
#include "physics/particle_solver.hpp"
#include "recon/refine/online_refine.hpp"
#include "recon/scene_particles.hpp"
#include "recon/tracker_sequence.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

struct ScanResult {
  std::unique_ptr<Volume> volume;  // null when tracking only
  TrackSequenceResult tracking;
  Mesh mesh;                                       // marching cubes of the volume (empty when tracking only)
  Intrinsics intrinsics{};                         // of the frames (undistorted)
  RgbdFrame first_frame;                           // host copy of the first frame (the Kinect view's fixed camera)
  std::int64_t unreadable = 0;                     // frames the source skipped as unreadable
  std::optional<OnlineRefineStats> online_refine;  // refine.online; tracking.trajectory is then the final graph's
  // The mesh's vertices the frames saw through (app/ghost.hpp; summary.json `ghost`): of the volume's
  // mesh, or when tracking only, of the tracker's own model (frame-to-model tracking or dynamic
  // handling build one); none without either.
  std::optional<SeenThroughGhost> seen_through;
};

// The seen-through ghost's slack for an experiment's volume: a truncation width (how far the
// mesh's zero crossing can lie from the surface) and 3 cm of pose error (app/ghost.hpp).
float seen_through_slack(const VolumeParams& v);

class RunRenderer;

// Tracks the experiment's input (and fuses it into a new volume when with_volume), writing
// trajectory.txt, tracking_stats.csv and, with a volume, mesh.ply (output.write_mesh). With
// refine.enabled or refine.online, trajectory.txt and tracking.trajectory are the refined poses,
// and the volume is fused at them in a second pass over the input (docs/TRACKING.md, "Refined
// poses in the scene").
// volume_stages: see TrackSequenceParams::volume_stages (`seamless bench pipeline`).
ScanResult scan(RunContext& ctx, bool with_volume, StageTimer* volume_stages = nullptr);

// Live mode (dissertation, section 5.2): track, fuse and simulate every frame; the scene particles
// are re-extracted from the volume every experiment.reextract_every fused frames. Returns each
// frame's tracking record; frame k's other stages (physics, extract, render) are ctx.timer()'s rows
// of frame k.
std::vector<FrameRecord> live(RunContext& ctx, RunRenderer* renderer, StageTimer* volume_stages = nullptr);

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

// The recording replayed under the simulation (render.camera: recorded): output frame k is input
// frame replay_start + k with its tracked pose, the solver advanced to that frame's time.
struct Replay {
  const Trajectory* trajectory = nullptr;  // one pose per input frame (the scan's)
  std::int64_t start = 0;
};

struct SimulationResult {
  ParticleState state;  // the last state, id order
  SolverStats stats;
};

// With a renderer, draws a frame every 1 / (render.fps * solver.dt) steps; with a replay, one
// frame per replayed input frame (then the simulation lasts as long as the replay, at least
// experiment.duration: a recording shorter than that plays forward and back).
// scene_particles: null for none; handed to the solver on their device (no host copy).
SimulationResult simulate(RunContext& ctx, const SceneParticles* scene_particles, const kernels::SceneSdf* sdf,
                          RunRenderer* renderer = nullptr, const SdfGrid* grid = nullptr,
                          const Replay* replay = nullptr);

}  // namespace seamless::app
