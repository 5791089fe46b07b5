// reconstruct, track, simulate: the pipeline's parts run on their own (render: cmd_render.cpp).
#include <spdlog/spdlog.h>

#include "app/commands.hpp"
#include "app/pipeline.hpp"
#include "app/run_context.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "kernels/scene/synthetic_room.hpp"
#include "recon/refine/refine.hpp"

namespace seamless::app {

void add_pipeline_commands(CLI::App& app, std::function<int()>& action) {
  auto rec = std::make_shared<CommonOptions>();
  auto* r = app.add_subcommand("reconstruct",
                               "track and fuse the input into the TSDF volume; write mesh.ply, "
                               "trajectory.txt and tracking_stats.csv");
  add_common_options(*r, *rec);
  r->callback([&action, rec] {
    action = [rec] {
      RunContext ctx(*rec);
      const ScanResult r = scan(ctx, true);
      write_scan_summary(ctx, "reconstruct", r);
      return ctx.exit_code();
    };
  });
  auto trk = std::make_shared<CommonOptions>();
  auto* t = app.add_subcommand("track", "track the camera over the input; write trajectory.txt and tracking_stats.csv");
  add_common_options(*t, *trk);
  t->callback([&action, trk] {
    action = [trk] {
      RunContext ctx(*trk);
      const Experiment& e = ctx.experiment();
      require_refine(e.refine);  // before tracking: a missing Ceres is not found out 150 frames later
      ScanResult r = scan(ctx, false);
      if (e.refine.enabled && e.refine.online)
        spdlog::info("refine: refine.online refined while tracking; the offline stage (refine.enabled) is skipped");
      const bool offline = e.refine.enabled && !e.refine.online;
      if (offline && interrupted()) spdlog::warn("refine: skipped (interrupted)");
      if (offline && !interrupted()) {
        std::vector<bool> tracked;
        for (const FrameRecord& f : r.tracking.frames) tracked.push_back(f.result.ok());
        refine_run(e.input, r.tracking.trajectory, tracked, e.refine, e.preprocess, ctx.device(), ctx.out_dir());
      }
      write_scan_summary(ctx, "track", r);
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
      if (ctx.experiment().input.source != InputSource::synthetic)
        throw ConfigError(
            "seamless simulate runs on the synthetic room's analytic scene (input.source: synthetic); to "
            "simulate on a scanned scene use `seamless run` with mode: scan_then_simulate");
      kernels::SceneSdf sdf{};
      sdf.synthetic_room = 1;
      ctx.experiment().solver.gravity = kernels::room::gravity();  // the room's world is z up
      simulate(ctx, nullptr, &sdf);
      return ctx.exit_code();
    };
  });
}

}  // namespace seamless::app
