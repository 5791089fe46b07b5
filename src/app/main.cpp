// The `seamless` command. Exit codes: app/exit_codes.hpp (README, "Exit codes and interrupted runs").
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <csignal>

#include "app/bench.hpp"
#include "app/commands.hpp"
#include "app/exit_codes.hpp"
#include "app/run_context.hpp"
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
  // A writer whose reader went away (ffmpeg) gets EPIPE and says so, instead of the process
  // being killed by SIGPIPE without a word.
  std::signal(SIGPIPE, SIG_IGN);
  int code = app::kExitUsage;
  auto fail = [&code](int c, const std::string& message) {
    spdlog::error("{}", message);
    app::annotate_failed_run(message, c);  // summary.json of the run, when one was started
    code = c;
  };
  try {
    if (action) code = action();
  } catch (const ConfigError& e) {
    fail(app::kExitConfig, e.what());
  } catch (const InputError& e) {
    fail(app::kExitInput, e.what());
  } catch (const UsageError& e) {
    fail(app::kExitUsage, e.what());
  } catch (const Error& e) {
    fail(app::kExitError, e.what());
  } catch (const std::bad_alloc&) {
    fail(app::kExitError, "out of memory (the config asks for more than this machine has: see the log for the stage)");
  } catch (const std::exception& e) {
    fail(app::kExitError, std::string("internal error: ") + e.what());
  }
  // A failure keeps its own code; a run that was stopped early otherwise says so, whatever it
  // would have returned for the frames it did.
  const bool failed = code != app::kExitOk && code != app::kExitLostFrames;
  if (interrupted() && !failed) {
    code = app::kExitSignalBase + interrupt_signal();
    if (!app::interruption_logged())
      spdlog::warn("stopped by {}: the outputs hold what was computed (exit code {})", signal_name(interrupt_signal()),
                   code);
  }
  spdlog::default_logger()->flush();
  return code;
}
