// eval, record, config.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <optional>

#include "app/commands.hpp"
#include "app/json_file.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "eval/trajectory_eval.hpp"
#include "io/frame_source.hpp"
#include "io/record.hpp"
#include "seamless/build_config.hpp"

namespace seamless::app {

namespace {
struct EvalArgs {
  std::vector<std::string> files;  // ground truth, estimate (evo's and TUM's order)
  EvalOptions opt;
  std::string align = "se3", json, aligned;
};

bool named_like_groundtruth(const std::string& path) {
  std::string name = std::filesystem::path(path).filename().string();
  std::transform(name.begin(), name.end(), name.begin(), [](unsigned char c) { return std::tolower(c); });
  return name.find("groundtruth") != std::string::npos || name.find("ground_truth") != std::string::npos ||
         name == "gt.txt" || name.rfind("gt_", 0) == 0;
}

bool named_like_estimate(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  // What seamless track and compare_trackers write, and ORB-SLAM's / ElasticFusion's usual names.
  for (const char* n :
       {"trajectory.txt", "trajectory_odometry.txt", "aligned.txt", "CameraTrajectory.txt", "KeyFrameTrajectory.txt"})
    if (name == n) return true;
  return false;
}

// `seamless eval` took the estimate first until 0.2; people type evo's order (ground truth
// first). Say so when the files look the other way round: the numbers are then those of the
// ground truth against the estimate, with the alignment and "N of M matched" on the wrong file.
void warn_if_swapped(const std::string& gt_path, const std::string& est_path, const Trajectory& gt,
                     const Trajectory& est) {
  std::string why;
  if (named_like_groundtruth(est_path) && !named_like_groundtruth(gt_path))
    why = "the second file is named like ground truth";
  else if (named_like_estimate(gt_path) && !named_like_estimate(est_path))
    why = "the first file is named like an estimated trajectory";
  else if (!named_like_groundtruth(gt_path) && est.size() > 2 * gt.size())
    // Motion capture (TUM: 100 Hz) samples far more often than a camera tracker (30 Hz).
    why = "the second file has " + std::to_string(est.size()) + " poses, more than twice the first's " +
          std::to_string(gt.size()) + ", as ground truth from motion capture usually has";
  if (why.empty()) return;
  spdlog::warn(
      "seamless eval takes GROUND TRUTH FIRST, then the estimate (evo_ape's and TUM's evaluate_ate.py's "
      "order; before seamless 0.2 it was the other way round), and {}: did you mean `seamless eval {} {}`?",
      why, est_path, gt_path);
}

void add_stats(Json& j, const std::string& prefix, const ErrorStats& s, const char* unit) {
  j[prefix + "_rmse_" + unit] = s.rmse, j[prefix + "_mean_" + unit] = s.mean;
  j[prefix + "_median_" + unit] = s.median, j[prefix + "_std_" + unit] = s.std;
  j[prefix + "_min_" + unit] = s.min, j[prefix + "_max_" + unit] = s.max;
}

bool same_file(const std::string& a, const std::string& b) {
  namespace fs = std::filesystem;
  std::error_code e1, e2;
  if (fs::equivalent(a, b, e1)) return true;
  const fs::path ca = fs::weakly_canonical(a, e1), cb = fs::weakly_canonical(b, e2);
  return !e1 && !e2 && ca == cb;
}

// `seamless eval gt est --json gt` would replace an input with the figures: refuse before reading.
void refuse_overwriting_inputs(const EvalArgs& a) {
  for (const auto& [option, out] : {std::pair{"--json", a.json}, std::pair{"--aligned", a.aligned}}) {
    if (out.empty()) continue;
    for (const std::string& in : a.files)
      if (same_file(out, in))
        throw UsageError(std::string(option) + " " + out + " is the input trajectory " + in +
                         ": eval never writes over its inputs; give another file name");
  }
  if (!a.json.empty() && !a.aligned.empty() && same_file(a.json, a.aligned))
    throw UsageError("--json and --aligned name the same file " + a.json + "; give two file names");
}

int run_eval(const EvalArgs& a) {
  refuse_overwriting_inputs(a);
  EvalOptions opt = a.opt;
  opt.align = parse_alignment(a.align);
  const std::string &gt_path = a.files[0], &est_path = a.files[1];
  const Trajectory gt = read_tum_trajectory(gt_path), est = read_tum_trajectory(est_path);
  warn_if_swapped(gt_path, est_path, gt, est);
  const AteResult ate = compute_ate(est, gt, opt);
  const RpeResult rpe_f = compute_rpe(est, gt, 1, "frames", opt);
  // TUM's RPE over 1 s (m/s, deg/s); a trajectory shorter than that has none.
  std::optional<RpeResult> rpe_s;
  std::string no_rpe_s;
  try {
    rpe_s = compute_rpe(est, gt, 1.0, "seconds", opt);
  } catch (const Error& e) {
    no_rpe_s = e.what();
  }
  std::printf("ground truth %s (%zu poses), estimate %s (%zu poses)\n", gt_path.c_str(), gt.size(), est_path.c_str(),
              est.size());
  std::printf("%zu of %zu estimated poses matched ground truth within %.3f s (offset %g s); alignment %s",
              ate.trans.count, est.size(), opt.t_max_diff, opt.offset, to_string(opt.align));
  if (opt.align == Alignment::sim3) std::printf(", scale %.6f", ate.scale);
  std::printf("\n%-24s %10s %10s %10s %10s %10s\n", "", "rmse", "mean", "median", "std", "max");
  auto row = [](const char* name, const ErrorStats& s, double scale) {
    std::printf("%-24s %10.4f %10.4f %10.4f %10.4f %10.4f\n", name, s.rmse * scale, s.mean * scale, s.median * scale,
                s.std * scale, s.max * scale);
  };
  row("ATE (cm)", ate.trans, 100);
  row("RPE/frame trans (cm)", rpe_f.trans, 100);
  row("RPE/frame rot (deg)", rpe_f.rot, 1);
  if (rpe_s) {
    row("RPE/1 s trans (cm/s)", rpe_s->trans, 100);
    row("RPE/1 s rot (deg/s)", rpe_s->rot, 1);
  } else {
    std::printf("no RPE over 1 s: %s\n", no_rpe_s.c_str());
  }
  if (!a.aligned.empty()) write_tum_trajectory(a.aligned, ate.aligned);
  if (!a.json.empty()) {
    // Schema: docs/TRACKING.md, "seamless eval".
    Json j = {{"schema", "seamless-eval/1"},    {"seamless_version", SEAMLESS_VERSION},
              {"groundtruth", gt_path},         {"estimate", est_path},
              {"groundtruth_poses", gt.size()}, {"estimate_poses", est.size()},
              {"t_max_diff_s", opt.t_max_diff}, {"offset_s", opt.offset},
              {"align", to_string(opt.align)},  {"scale", ate.scale},
              {"pairs", ate.trans.count}};
    add_stats(j, "ate", ate.trans, "m");
    j["rpe_frame_pairs"] = rpe_f.trans.count;
    add_stats(j, "rpe_frame_trans", rpe_f.trans, "m");
    add_stats(j, "rpe_frame_rot", rpe_f.rot, "deg");
    j["rpe_second_delta_s"] = 1.0;
    if (rpe_s) {
      j["rpe_second_pairs"] = rpe_s->trans.count;
      add_stats(j, "rpe_second_trans", rpe_s->trans, "m");  // metres over 1 s: m/s
      add_stats(j, "rpe_second_rot", rpe_s->rot, "deg");    // deg/s
    } else {
      j["rpe_second_pairs"] = 0;
      for (const char* k : {"rpe_second_trans_rmse_m", "rpe_second_rot_rmse_deg"}) j[k] = nullptr;
    }
    write_json_file(a.json, j);
  }
  return 0;
}
}  // namespace

void add_eval_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<EvalArgs>();
  auto* cmd = app.add_subcommand(
      "eval", "ATE and RPE of an estimated trajectory against ground truth (TUM format; ground truth first, as evo)");
  cmd->add_option("trajectories", a->files, "groundtruth.txt estimate.txt (evo's and TUM's order)")
      ->expected(2)
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--t_max_diff,--max-dt", a->opt.t_max_diff,
                  "largest timestamp difference of associated poses, seconds (TUM: 0.02, evo: 0.01)")
      ->check(CLI::Validator(
          [](const std::string& s) {
            double v = -1;
            try {
              v = std::stod(s);
            } catch (const std::exception&) {
            }
            return v >= 0 ? std::string() : "is " + s + "; a timestamp difference is 0 s or more";
          },
          "SECONDS >= 0"))
      ->capture_default_str();
  cmd->add_option("--offset", a->opt.offset, "seconds added to the estimate's timestamps before association")
      ->capture_default_str();
  cmd->add_option("--align", a->align, "alignment before ATE: se3 (rigid), sim3 (rigid + scale) or none")
      ->check(CLI::IsMember({"se3", "sim3", "none"}))
      ->capture_default_str();
  cmd->add_option("--json", a->json, "write the figures as JSON (schema in docs/TRACKING.md)");
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
  // The folder first (lock, --out over the input refused), then the source: nothing is read or
  // written for a folder that cannot be used.
  OutputFolder folder(a.out, a.force, input_paths(e), {"rgb.txt", "depth.txt", "associations.txt", "manifest.txt"});
  auto source = make_source(e.input, resolve_device(a.device));
  install_interrupt_handlers();  // record() stops after the frame being written
  RecordOptions o;
  o.max_frames = a.frames;
  std::int64_t n = 0;
  try {
    n = record(*source, a.out, o);
  } catch (...) {
    folder.remove_partial_files();
    folder.write_manifest("record");
    throw;
  }
  folder.remove_partial_files();
  folder.write_manifest("record");
  spdlog::info("recorded {} frames from {} into {} (TUM format; read back with input.source: tum, input.path: {})", n,
               source->name(), a.out, a.out);
  return 0;
}
}  // namespace

void add_record_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<RecordArgs>();
  auto* cmd = app.add_subcommand("record", "write a source (Kinect, synthetic room, TUM) as a TUM-format folder");
  cmd->add_option("config", a->config, "experiment file whose input section to use (optional)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--source", a->source, "synthetic, tum or kinect (overrides input.source)")
      ->check(CLI::IsMember({"synthetic", "tum", "kinect"}));
  cmd->add_option("--path", a->path, "TUM folder when --source tum");
  cmd->add_option("--out", a->out, "folder to write")->required();
  cmd->add_option("--frames", a->frames,
                  "stop after this many frames, at least 1 (left out: until the source ends; Ctrl-C stops after the "
                  "frame being written, leaving a folder that loads)")
      ->check(frame_count(1, "leave it out to record until the source ends"));
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
  cmd->add_flag("--list", *list,
                "print every key with type, default and meaning (Markdown); `config --list tracker`: the keys of "
                "that section (or that key)");
  cmd->callback([&action, o, list] {
    action = [o, list] {
      if (*list) {
        // The positional argument names a section or key here, not a file.
        const std::string md = experiment_keys_markdown(o->config);
        if (md.empty())
          throw UsageError("config --list " + o->config +
                           ": no such section or key (`seamless config --list` prints them all)");
        std::fputs(md.c_str(), stdout);
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
