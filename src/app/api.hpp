// The subcommands as functions: what `seamless track|reconstruct|simulate|run|eval` do once their
// options are parsed. The CLI's actions (cmd_*.cpp) and the Python module (python/) call these, so
// both run the same code and write the same files.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "app/pipeline.hpp"
#include "app/run_context.hpp"
#include "app/run_summary.hpp"
#include "eval/trajectory_eval.hpp"

namespace seamless::app {

// seamless track: tracks the input, then (refine.enabled, offline) refines the trajectory;
// tracking.trajectory is then the refined one, as trajectory.txt.
ScanResult track_experiment(RunContext& ctx);

// seamless reconstruct: tracks and fuses the input; mesh.ply, trajectory.txt, tracking_stats.csv.
ScanResult reconstruct_experiment(RunContext& ctx);

// seamless simulate: the particle solver on the synthetic room's exact SDF (no scan).
SimulationResult simulate_experiment(RunContext& ctx);

// What `seamless run` computed. live: mode live (then scan and the particles are empty and
// live_frames holds each frame's tracking record).
struct RunOutputs {
  bool live = false;
  std::vector<FrameRecord> live_frames;
  ScanResult scan;
  std::vector<vec3> scene_particles;  // host copy, as scene_particles.ply
  SimulationResult simulation;
  RunSummary summary;  // as summary.json
};

// seamless run (mode scan_then_simulate or live); `config` names the experiment in summary.json.
RunOutputs run_experiment(RunContext& ctx, const std::string& config);

// seamless eval's figures as the JSON text its --json writes (schema in docs/TRACKING.md); warns, as
// the CLI does, when the files look swapped.
std::string eval_report(const std::string& groundtruth, const std::string& estimate, const EvalOptions& options);

}  // namespace seamless::app
