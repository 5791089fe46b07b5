// eval, record, config.
#include <spdlog/spdlog.h>

#include <cstdio>

#include "app/commands.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "eval/trajectory_eval.hpp"
#include "io/frame_source.hpp"
#include "io/record.hpp"

namespace seamless::app {

namespace {
struct EvalArgs {
  std::vector<std::string> files;
  double max_dt = 0.02;
  std::string json, aligned;
};

int run_eval(const EvalArgs& a) {
  Trajectory est = read_tum_trajectory(a.files[0]), gt = read_tum_trajectory(a.files[1]);
  AteResult ate = compute_ate(est, gt, a.max_dt);
  RpeResult rpe_f = compute_rpe(est, gt, 1, "frames", a.max_dt);
  double span = est.empty() ? 0 : est.back().timestamp - est.front().timestamp;
  std::printf("%zu of %zu estimated poses matched ground truth within %.3f s\n", ate.trans.count, est.size(), a.max_dt);
  std::printf("%-22s %10s %10s %10s %10s\n", "", "rmse", "mean", "median", "max");
  auto row = [](const char* name, const ErrorStats& s, double scale) {
    std::printf("%-22s %10.4f %10.4f %10.4f %10.4f\n", name, s.rmse * scale, s.mean * scale, s.median * scale,
                s.max * scale);
  };
  row("ATE (cm)", ate.trans, 100);
  row("RPE/frame trans (cm)", rpe_f.trans, 100);
  row("RPE/frame rot (deg)", rpe_f.rot, 1);
  std::string rpe_s_json;
  if (span > 1.0) {
    RpeResult rpe_s = compute_rpe(est, gt, 1.0, "seconds", a.max_dt);
    row("RPE/s trans (cm)", rpe_s.trans, 100);
    row("RPE/s rot (deg)", rpe_s.rot, 1);
    rpe_s_json = ",\n  \"rpe_second_trans_rmse_m\": " + std::to_string(rpe_s.trans.rmse) +
                 ",\n  \"rpe_second_rot_rmse_deg\": " + std::to_string(rpe_s.rot.rmse);
  }
  if (!a.aligned.empty()) write_tum_trajectory(a.aligned, ate.aligned);
  if (!a.json.empty()) {
    std::FILE* f = std::fopen(a.json.c_str(), "w");
    if (!f) throw Error("cannot write " + a.json);
    std::fprintf(f,
                 "{\n  \"pairs\": %zu,\n  \"ate_rmse_m\": %.9f,\n  \"ate_mean_m\": %.9f,\n  \"ate_median_m\": %.9f,\n"
                 "  \"ate_max_m\": %.9f,\n  \"rpe_frame_trans_rmse_m\": %.9f,\n  \"rpe_frame_rot_rmse_deg\": %.9f%s\n}\n",
                 ate.trans.count, ate.trans.rmse, ate.trans.mean, ate.trans.median, ate.trans.max, rpe_f.trans.rmse,
                 rpe_f.rot.rmse, rpe_s_json.c_str());
    std::fclose(f);
  }
  return 0;
}
}  // namespace

void add_eval_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand("eval", "ATE and RPE of an estimated trajectory against ground truth (TUM format)");
  cmd->add_option("trajectories", a->files, "estimate.txt groundtruth.txt")->expected(2)->required()->check(CLI::ExistingFile);
  cmd->add_option("--max-dt", a->max_dt, "largest timestamp difference of associated poses, seconds (TUM: 0.02)");
  cmd->add_option("--json", a->json, "write the figures as JSON");
  cmd->add_option("--aligned", a->aligned, "write the aligned estimate (TUM format) for plotting");
  cmd->callback([&action, a] { action = [a] { return run_eval(*a); }; });
}

namespace {
struct RecordArgs {
  std::string config, source, out, device = "auto", path;
  std::vector<std::string> sets;
  std::int64_t frames = 0;
  bool force = false;
};

int run_record(const RecordArgs& a) {
  std::vector<std::string> sets = a.sets;
  if (!a.source.empty()) sets.push_back("input.source=" + a.source);
  if (!a.path.empty()) sets.push_back("input.path=" + a.path);
  Experiment e = a.config.empty() ? parse_experiment("{}", sets, "<defaults>") : load_experiment(a.config, sets);
  auto source = make_source(e.input, resolve_device(a.device));
  prepare_output_folder(a.out, a.force, {"rgb.txt", "depth.txt", "associations.txt"});
  install_interrupt_handlers();  // record() stops after the frame being written
  RecordOptions o;
  o.max_frames = a.frames;
  std::int64_t n = record(*source, a.out, o);
  spdlog::info("recorded {} frames from {} into {} (TUM format; read back with input.source: tum, input.path: {})", n,
               source->name(), a.out, a.out);
  return 0;
}
}  // namespace

void add_record_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<RecordArgs>();
  auto* cmd = app.add_subcommand("record", "write a source (Kinect, synthetic room, TUM) as a TUM-format folder");
  cmd->add_option("config", a->config, "experiment file whose input section to use (optional)")->check(CLI::ExistingFile);
  cmd->add_option("--source", a->source, "synthetic, tum or kinect (overrides input.source)")
      ->check(CLI::IsMember({"synthetic", "tum", "kinect"}));
  cmd->add_option("--path", a->path, "TUM folder when --source tum");
  cmd->add_option("--out", a->out, "folder to write")->required();
  cmd->add_option("--frames", a->frames,
                  "stop after this many frames (0: until the source ends; Ctrl-C stops after the frame being written, "
                  "leaving a folder that loads)");
  cmd->add_flag("--force", a->force, "write into a folder that holds an earlier recording after clearing it");
  cmd->add_option("--set", a->sets, "override a config key, e.g. --set input.synthetic.frames=30");
  cmd->add_option("--device", a->device, "where the synthetic room renders: cpu, cuda or auto");
  cmd->callback([&action, a] { action = [a] { return run_record(*a); }; });
}

void add_config_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<CommonOptions>();
  auto* cmd = app.add_subcommand("config", "check an experiment file, print its effective form, or list every key");
  add_common_options(*cmd, *o, false);
  auto list = std::make_shared<bool>(false);
  cmd->add_flag("--list", *list, "print every key with type, default and meaning (Markdown)");
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
      std::fputs(to_yaml(load_experiment(o->config, overrides(*o))).c_str(), stdout);
      return 0;
    };
  });
}

}  // namespace seamless::app
