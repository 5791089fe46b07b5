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

void add_pipeline_commands(CLI::App& app, std::function<int()>& action) {
  auto rec = std::make_shared<CommonOptions>();
  auto* r = app.add_subcommand("reconstruct",
                               "track and fuse the input into the TSDF volume; write mesh.ply, "
                               "trajectory.txt and tracking_stats.csv");
  add_common_options(*r, *rec);
  add_frames_option(*r, *rec);
  r->callback([&action, rec] {
    action = [rec] {
      RunContext ctx(*rec);
      reconstruct_experiment(ctx);
      return ctx.exit_code();
    };
  });
  auto trk = std::make_shared<CommonOptions>();
  auto* t = app.add_subcommand("track", "track the camera over the input; write trajectory.txt and tracking_stats.csv");
  add_common_options(*t, *trk);
  add_frames_option(*t, *trk);
  t->callback([&action, trk] {
    action = [trk] {
      RunContext ctx(*trk);
      track_experiment(ctx);
      return ctx.exit_code();
    };
  });
  auto sim = std::make_shared<CommonOptions>();
  auto* m = app.add_subcommand("simulate",
                               "run the particle solver on the synthetic room's exact SDF (no scan); "
                               "write particle states");
  add_common_options(*m, *sim);
  m->callback([&action, sim] {
    action = [sim] {
      RunContext ctx(*sim);
      simulate_experiment(ctx);
      return ctx.exit_code();
    };
  });
}

}  // namespace seamless::app
