// eval, record, config.
#include <spdlog/spdlog.h>

#include <cstdio>

#include "app/commands.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"

namespace seamless::app {

void add_eval_command(CLI::App& app, std::function<int()>& action) {
  auto files = std::make_shared<std::vector<std::string>>();
  auto* cmd = app.add_subcommand("eval", "ATE and RPE of an estimated trajectory against ground truth (TUM format)");
  cmd->add_option("trajectories", *files, "estimate.txt groundtruth.txt")->expected(2)->required();
  cmd->callback([&action] { action = [] { return not_built("eval", "trajectory evaluation (issue 5) is not built yet"); }; });
}

void add_record_command(CLI::App& app, std::function<int()>& action) {
  auto* cmd = app.add_subcommand("record", "write a source (Kinect, synthetic room, TUM) as a TUM-format folder");
  cmd->callback([&action] { action = [] { return not_built("record", "recording (issue 3) is not wired yet"); }; });
}

void add_config_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<CommonOptions>();
  auto* cmd = app.add_subcommand("config", "check an experiment file, print its effective form, or list every key");
  add_common_options(*cmd, *o, false);
  auto* list = cmd->add_flag("--list", "print every key with type, default and meaning (Markdown)");
  cmd->callback([&action, o, list] {
    action = [o, list] {
      if (*list) {
        std::fputs(experiment_keys_markdown().c_str(), stdout);
        return 0;
      }
      if (o->config.empty()) {
        spdlog::error("seamless config: give an experiment file, or --list");
        return 2;
      }
      std::vector<std::string> sets = o->sets;
      if (!o->device.empty()) sets.push_back("device=" + o->device);
      std::fputs(to_yaml(load_experiment(o->config, sets)).c_str(), stdout);
      return 0;
    };
  });
}

}  // namespace seamless::app
