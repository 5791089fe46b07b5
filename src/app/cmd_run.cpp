// seamless run <config>: the whole flow from one experiment file. Stages that are not built yet
// are named in the log and skipped; nothing is faked (README, section Status).
#include <spdlog/spdlog.h>

#include <memory>

#include "app/commands.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "recon/preprocess.hpp"

namespace seamless::app {

namespace {

int dry_run(const CommonOptions& o) {
  std::vector<std::string> sets = o.sets;
  if (!o.device.empty()) sets.push_back("device=" + o.device);
  Experiment e = load_experiment(o.config, sets);
  spdlog::info("{}: valid ({} spawn entries, input {}, device {})", o.config, e.spawn.size(), e.input.source,
               e.device);
  return 0;
}

int run(const CommonOptions& o) {
  if (o.dry_run) return dry_run(o);
  RunContext ctx(o);
  const Experiment& e = ctx.experiment();
  auto source = make_source(e.input, ctx.device());
  Intrinsics K = source->intrinsics();
  FramePyramid pyramid(ctx.device(), K, e.preprocess.levels);
  spdlog::warn("not built yet, skipped: tracking, TSDF fusion, scene extraction, physics, rendering");

  std::int64_t limit = e.frames > 0 ? e.frames : source->size().value_or(0);
  Progress progress("frames", limit);
  RgbdFrame frame;
  std::int64_t n = 0;
  while ((limit == 0 || n < limit) && source->next(frame)) {
    {
      StageScope s(ctx.timer(), "upload");
      Image<float> depth = frame.depth.clone(ctx.device());
      StageScope p(ctx.timer(), "preprocess");
      pyramid.build(depth, nullptr, e.preprocess);
    }
    ctx.timer().end_frame(n);
    progress.update(++n);
  }
  progress.finish();
  spdlog::info("{} frames from {} ({} skipped); median preprocess {:.3f} ms", n, source->name(),
               source->skipped_frames(), ctx.timer().median_ms("preprocess"));
  spdlog::info("outputs in {}", ctx.out_dir());
  return 0;
}

}  // namespace

void add_run_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<CommonOptions>();
  auto* cmd = app.add_subcommand("run", "run an experiment end to end: input, reconstruction, physics, rendering");
  add_common_options(*cmd, *o);
  cmd->add_flag("--dry-run", o->dry_run, "validate the config and exit");
  cmd->callback([&action, o] { action = [o] { return run(*o); }; });
}

}  // namespace seamless::app
