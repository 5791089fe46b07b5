// reconstruct, track, simulate: the pipeline's parts run on their own (render: cmd_render.cpp).
#include <spdlog/spdlog.h>

#include "app/api.hpp"
#include "app/commands.hpp"
#include "app/pipeline.hpp"
#include "app/run_context.hpp"
#include "app/run_summary.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "kernels/scene/synthetic_room.hpp"
#include "recon/refine/refine.hpp"

namespace seamless::app {

ScanResult reconstruct_experiment(RunContext& ctx) {
  ScanResult s = scan(ctx, true);
  add_tracking(ctx.summary(), s.tracking, s.unreadable, groundtruth_path(ctx));
  ctx.summary().intrinsics = s.intrinsics;
  ctx.summary().seen_through = s.seen_through;
  return s;
}

ScanResult track_experiment(RunContext& ctx) {
  ScanResult r = scan(ctx, false);  // refines too (refine.enabled / refine.online)
  // summary.json as `run` writes it, for the trajectory.txt written (refined, when refine is on).
  add_tracking(ctx.summary(), r.tracking, r.unreadable, groundtruth_path(ctx));
  ctx.summary().intrinsics = r.intrinsics;
  ctx.summary().seen_through = r.seen_through;
  ctx.summary().online_refine = r.online_refine;
  return r;
}

SimulationResult simulate_experiment(RunContext& ctx) {
  if (ctx.experiment().input.source != InputSource::synthetic)
    throw ConfigError(
        "seamless simulate runs on the synthetic room's analytic scene (input.source: synthetic); to "
        "simulate on a scanned scene use `seamless run` with mode: scan_then_simulate");
  kernels::SceneSdf sdf{};
  sdf.synthetic_room = 1;
  ctx.experiment().solver.gravity = kernels::room::gravity();  // the room's world is z up
  SimulationResult result = simulate(ctx, nullptr, &sdf);
  ctx.summary().physics = result.stats;
  return result;
}

namespace {

// A subcommand that runs `run` on the experiment its options name (with --frames where `frames`):
// it sets the action of the command line to that run, which returns the run's exit code.
template <class Run>
void add_experiment_command(CLI::App& app, std::function<int()>& action, const char* name, const char* help,
                            bool frames, Run run) {
  auto opts = std::make_shared<CommonOptions>();
  auto* c = app.add_subcommand(name, help);
  add_common_options(*c, *opts);
  if (frames) add_frames_option(*c, *opts);
  c->callback([&action, opts, run] {
    action = [opts, run] {
      RunContext ctx(*opts);
      run(ctx);
      return ctx.exit_code();
    };
  });
}

}  // namespace

void add_pipeline_commands(CLI::App& app, std::function<int()>& action) {
  add_experiment_command(app, action, "reconstruct",
                         "track and fuse the input into the TSDF volume; write mesh.ply, "
                         "trajectory.txt and tracking_stats.csv",
                         true, reconstruct_experiment);
  add_experiment_command(app, action, "track",
                         "track the camera over the input; write trajectory.txt and tracking_stats.csv", true,
                         track_experiment);
  add_experiment_command(app, action, "simulate",
                         "run the particle solver on the synthetic room's exact SDF (no scan); "
                         "write particle states",
                         false, simulate_experiment);
}

}  // namespace seamless::app
