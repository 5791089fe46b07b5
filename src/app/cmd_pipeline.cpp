// reconstruct, track, simulate, render: the pipeline's parts run on their own.
#include "app/commands.hpp"
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
      {"reconstruct", "fuse the input into the TSDF volume; write mesh.ply and trajectory.txt",
       "the voxel-hashed TSDF (issue 4) is not wired into the command yet"},
      {"track", "track the camera over the input; write trajectory.txt and per-frame tracking stats",
       "the ICP and RGB-D trackers (issue 5) are not built yet"},
      {"simulate", "run the particle solver on a static scene; write particle states or frames",
       "the unified particle solver (issue 6) is not wired into the command yet"},
      {"render", "render a run's outputs (mesh, particles, fluid) to images or a window",
       "the renderer (issue 7) is not built yet"},
  };
  for (const Part& p : parts) {
    auto o = std::make_shared<CommonOptions>();
    auto* cmd = app.add_subcommand(p.name, p.help);
    add_common_options(*cmd, *o);
    cmd->callback([&action, p] { action = [p] { return not_built(p.name, p.missing); }; });
  }
}

}  // namespace seamless::app
