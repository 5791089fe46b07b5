// The `seamless` command. Exit codes: 0 done, 1 error (message names the problem), 2 bad usage,
// 3 the asked-for part of the pipeline is not built yet.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>

#include "app/bench.hpp"
#include "app/commands.hpp"
#include "core/error.hpp"
#include "core/log.hpp"
#include "seamless/build_config.hpp"

int main(int argc, char** argv) {
  using namespace seamless;
  CLI::App app{"seamless: scan a room with a depth camera, then let virtual rigid bodies, cloth and fluid live in it"};
  app.require_subcommand(1);
  app.set_version_flag("--version", SEAMLESS_VERSION);
  bool quiet = false, verbose = false;
  app.add_flag("-q,--quiet", quiet, "warnings and errors only");
  app.add_flag("-v,--verbose", verbose, "debug output");

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
    return app.exit(e);
  }
  init_logging(quiet ? Verbosity::Quiet : verbose ? Verbosity::Verbose : Verbosity::Normal);
  try {
    return action ? action() : 2;
  } catch (const Error& e) {
    spdlog::error("{}", e.what());
    return 1;
  } catch (const std::exception& e) {
    spdlog::error("internal error: {}", e.what());
    return 1;
  }
}
