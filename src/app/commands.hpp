// Each subcommand registers itself on the CLI and, when chosen, sets `action` (run after parsing).
#pragma once
#include <CLI/CLI.hpp>

#include <functional>

namespace seamless::app {
void add_run_command(CLI::App& app, std::function<int()>& action);
void add_pipeline_commands(CLI::App& app, std::function<int()>& action);  // reconstruct, track, simulate
void add_render_command(CLI::App& app, std::function<int()>& action);     // cmd_render.cpp
void add_eval_command(CLI::App& app, std::function<int()>& action);
void add_bench_command(CLI::App& app, std::function<int()>& action);
void add_record_command(CLI::App& app, std::function<int()>& action);
void add_config_command(CLI::App& app, std::function<int()>& action);
}  // namespace seamless::app
