// reconstruct, track, simulate, render: the pipeline's parts run on their own.
#include "app/commands.hpp"
#include "app/pipeline.hpp"
#include "app/run_context.hpp"

namespace seamless::app {

namespace {
struct Part {
  const char* name;
  const char* help;
  const char* missing;
};
}  // namespace

void add_pipeline_commands(CLI::App& app, std::function<int()>& action) {
  static const Part parts[] = {
      {"simulate", "run the particle solver on a static scene; write particle states or frames",
       "the unified particle solver (issue 6) is not wired into the command yet"},
      {"render", "render a run's outputs (mesh, particles, fluid) to images or a window",
       "the renderer (issue 7) is not built yet"},
  };
  auto rec = std::make_shared<CommonOptions>();
  auto* r = app.add_subcommand("reconstruct", "track and fuse the input into the TSDF volume; write mesh.ply, "
                                              "trajectory.txt and tracking_stats.csv");
  add_common_options(*r, *rec);
  r->callback([&action, rec] {
    action = [rec] {
      RunContext ctx(*rec);
      scan(ctx, true);
      return 0;
    };
  });
  auto trk = std::make_shared<CommonOptions>();
  auto* t = app.add_subcommand("track", "track the camera over the input; write trajectory.txt and tracking_stats.csv");
  add_common_options(*t, *trk);
  t->callback([&action, trk] {
    action = [trk] {
      RunContext ctx(*trk);
      scan(ctx, false);
      return 0;
    };
  });
  for (const Part& p : parts) {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = app.add_subcommand(p.name, p.help);
    add_common_options(*cmd, *o);
    cmd->callback([&action, p] { action = [p] { return not_built(p.name, p.missing); }; });
  }
}

}  // namespace seamless::app
