// The `seamless` command. Exit codes: app/exit_codes.hpp (README, "Exit codes and interrupted runs").
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "app/bench.hpp"
#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

int main(int argc, char** argv) {
  using namespace seamless;
  CLI::App app{"seamless: scan a room with a depth camera, then let virtual rigid bodies, cloth and fluid live in it"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SEAMLESS_VERSION);
  app.footer(app::kExitCodesHelp);
  bool quiet = false, verbose = false;
  app.add_flag("-q,--quiet", quiet, "warnings and errors only");
  app.add_flag("-v,--verbose", verbose, "debug output");
  // `seamless run cfg.yaml -q` as well as `seamless -q run cfg.yaml`: what a subcommand does not
  // know goes to these options (and is a usage error there when no one knows it).
  app.fallthrough();

  std::function<int()> action;
  app::add_run_command(app, action);
  app::add_pipeline_commands(app, action);
  app::add_render_command(app, action);
  app::add_eval_command(app, action);
  app::add_bench_command(app, action);
  app::add_record_command(app, action);
  app::add_config_command(app, action);
  app::register_benchmarks();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? app::kExitOk : app::kExitUsage;  // --help and --version exit 0
  }
  init_logging(quiet ? Verbosity::Quiet : verbose ? Verbosity::Verbose : Verbosity::Normal);
  spdlog::debug("seamless {} (commit {}), debug output on", SEAMLESS_VERSION, SEAMLESS_GIT_COMMIT);
  int code = app::kExitUsage;
  try {
    if (action) code = action();
  } catch (const ConfigError& e) {
    spdlog::error("{}", e.what());
    code = app::kExitConfig;
  } catch (const InputError& e) {
    spdlog::error("{}", e.what());
    code = app::kExitInput;
  } catch (const UsageError& e) {
    spdlog::error("{}", e.what());
    code = app::kExitUsage;
  } catch (const Error& e) {
    spdlog::error("{}", e.what());
    code = app::kExitError;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    code = app::kExitError;
  }
  // A failure keeps its own code; a run that was stopped early otherwise says so, whatever it
  // would have returned for the frames it did.
  const bool failed = code != app::kExitOk && code != app::kExitLostFrames;
  if (interrupted() && !failed) {
    code = app::kExitSignalBase + interrupt_signal();
    spdlog::warn("stopped by a signal: the outputs hold what was computed (exit code {})", code);
  }
  spdlog::default_logger()->flush();
  return code;
}
