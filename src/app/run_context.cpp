#include "app/run_context.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <exception>
#include <filesystem>
#include <fstream>
#include <set>

#include "app/json_file.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "core/output_file.hpp"

namespace seamless::app {

namespace fs = std::filesystem;

void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required) {
  o.command = cmd.get_name();
  auto* c = cmd.add_option("config", o.config, "experiment file (YAML), e.g. configs/demo.yaml");
  if (config_required) c->required()->check(CLI::ExistingFile);
  cmd.add_option("--set", o.sets, "override a config key: --set volume.voxel_size=0.01 (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--out", o.out, "output folder (default: <output.dir>/<config name>-<date-time>)");
  cmd.add_flag("--force", o.force, "write into an output folder that holds an earlier run after clearing it");
  cmd.add_option("--device", o.device, "cpu, cuda or auto (overrides the config's device)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}));
}

void add_frames_option(CLI::App& cmd, CommonOptions& o) {
  cmd.add_option("--frames", o.frames,
                 "process this many input frames (the key `frames`; 0: all the input has; with input.max_frames "
                 "also set, the smaller of the two)")
      ->check(frame_count(0, "0 or leaving it out: all the input has"));
}

CLI::Validator frame_count(std::int64_t min, const std::string& hint) {
  return CLI::Validator(
      [min, hint](const std::string& s) {
        std::int64_t v = 0;
        std::size_t used = 0;
        try {
          v = std::stoll(s, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == s.size() && v >= min) return std::string();
        return "is " + s + "; give a whole number of frames, at least " + std::to_string(min) + " (" + hint + ")";
      },
      "FRAMES >= " + std::to_string(min));
}

std::vector<std::string> overrides(const CommonOptions& o) {
  std::vector<std::string> sets = o.sets;
  if (o.frames >= 0) sets.push_back("frames=" + std::to_string(o.frames));
  if (!o.device.empty()) sets.push_back("device=" + o.device);
  return sets;
}

std::string groundtruth_path(const RunContext& ctx) {
  if (fs::exists(ctx.out_path("groundtruth.txt"))) return ctx.out_path("groundtruth.txt");
  const InputParams& in = ctx.experiment().input;
  const std::string gt = in.path + "/groundtruth.txt";
  return in.source == InputSource::tum && fs::exists(gt) ? gt : "";
}

std::vector<std::string> input_paths(const Experiment& e) {
  std::vector<std::string> paths;
  if (e.input.source == InputSource::tum || e.input.source == InputSource::frames) paths.push_back(e.input.path);
  paths.push_back(e.input.intrinsics.file);
  for (const SpawnParams& s : e.spawn) paths.push_back(s.mesh);
  return paths;
}

namespace {
std::string timestamp() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&t));
  return buf;
}

}  // namespace

RunContext::RunContext(const CommonOptions& o) : RunContext(o, load_experiment(o.config, overrides(o))) {}

RunContext::RunContext(const CommonOptions& o, Experiment e) : exp_(std::move(e)), window_frames_(o.window_frames) {
  device_ = resolve_device(exp_.device);

  out_ = o.out.empty() ? exp_.output.dir + "/" + fs::path(o.config).stem().string() + "-" + timestamp() : o.out;
  // What every run writes first: a folder holding one of these holds another run.
  folder_ = std::make_unique<OutputFolder>(out_, o.force, input_paths(exp_),
                                           std::vector<std::string>{"config.yaml", "log.txt", "summary.json"});
  command_ = o.command.empty() ? "run" : o.command;
  log_file_ = log_to_file(out_path("log.txt"));
  if (exp_.output.write_config) write_effective_config(exp_, out_path("config.yaml"));
  timer_ = std::make_unique<StageTimer>(device_);
  install_interrupt_handlers();
  summary_.command = command_, summary_.config = o.config, summary_.device = device_name(device_);
  // Two limits on the frames read; the smaller one holds (docs/CONFIG.md, `frames`).
  if (exp_.frames > 0 && exp_.input.max_frames > 0 && exp_.frames != exp_.input.max_frames)
    spdlog::info("frames = {} and input.max_frames = {}: the run reads at most {} frames (the smaller of the two)",
                 exp_.frames, exp_.input.max_frames, std::min(exp_.frames, exp_.input.max_frames));
  // Until the run ends, its summary says so: a run killed outright (a second Ctrl-C, SIGKILL, a
  // crash) leaves this mark, and the lock tells a run still going from one that was killed.
  RunSummary mark = summary_;
  mark.status = "incomplete", mark.reached_frames = 0, mark.reached_steps = 0;
  write_summary(out_path("summary.json"), mark);
  uncaught_ = std::uncaught_exceptions();

  std::string gpu = device_ == Device::CUDA ? " (" + cuda_device_description() + ")" : "";
  spdlog::info("experiment '{}' from {}, device {}{}, output {}", exp_.name, o.config, device_name(device_), gpu, out_);
}

void RunContext::report_tracking(std::int64_t frames, std::int64_t lost, std::int64_t dropped_blocks) {
  if (frames <= 0) return;
  const double fraction = static_cast<double>(lost) / static_cast<double>(frames);
  if (fraction <= exp_.output.max_lost_fraction) return;
  exit_code_ = kExitLostFrames;
  if (dropped_blocks > 0)
    return spdlog::error(
        "tracking lost {} of {} frames ({:.0f}%), more than output.max_lost_fraction = {} (exit code {}): the volume "
        "dropped {} block insertions (its block pool or hash table was full with volume.grow_when_full: false), so "
        "frames were tracked against a model with holes. Raise volume.capacity and volume.hash_buckets as the "
        "warnings above say, or set volume.grow_when_full: true",
        lost, frames, 100 * fraction, exp_.output.max_lost_fraction, kExitLostFrames, dropped_blocks);
  spdlog::error(
      "tracking lost {} of {} frames ({:.0f}%), more than output.max_lost_fraction = {}: the trajectory and "
      "the model are not to be trusted (exit code {}). tracking_stats.csv says why each frame was lost; "
      "check input.depth_scale (TUM: 5000, millimetres: 1000), input.intrinsics and the tracker section",
      lost, frames, 100 * fraction, exp_.output.max_lost_fraction, kExitLostFrames);
}

void RunContext::report_output_failure(const std::string& what) {
  spdlog::error("{} (the run's other outputs are written; exit code {})", what, kExitError);
  if (exit_code_ == kExitOk) exit_code_ = kExitError;
}

namespace {
std::string g_failed_summary;  // summary.json of the run that failed last (annotate_failed_run)
bool g_interruption_logged = false;

std::string summary_status(const std::string& path) {
  std::ifstream in(path);
  const Json j = in ? Json::parse(in, nullptr, false) : Json();
  return j.is_object() ? j.value("status", "") : "";
}
}  // namespace

void RunContext::finish_summary(bool failed) noexcept {
  try {
    const std::string path = out_path("summary.json");
    // The command wrote its full summary (run): it stands, unless the run failed after it.
    if (!failed && summary_status(path) != "incomplete") return;
    std::set<std::int64_t> frames;
    std::int64_t steps = 0;
    for (const StageTimer::Row& r : timer_->rows()) {
      if (r.stage == "track") frames.insert(r.frame);
      steps += r.stage == "physics";
    }
    summary_.reached_frames = std::max<std::int64_t>(summary_.frames_read, static_cast<std::int64_t>(frames.size()));
    summary_.reached_steps = steps;
    if (failed) summary_.status = "failed";
    if (summary_.stage_median_ms.empty()) add_stage_medians(summary_, *timer_);
    write_summary(path, summary_);
    if (failed) g_failed_summary = path;
  } catch (const std::exception& e) {
    spdlog::error("summary.json: {}", e.what());
  }
}

RunContext::~RunContext() {
  const bool failed = std::uncaught_exceptions() > uncaught_;
  if (exp_.output.write_timings && timer_ && !timer_->rows().empty()) {
    try {
      timer_->write_csv(out_path("timings.csv"));
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
    }
  }
  if (!failed && interrupted() && (g_interruption_logged = true))  // into log.txt: why it stopped early
    spdlog::warn("stopped by {}: the outputs hold what was computed (summary.json: \"interrupted\", exit code {})",
                 signal_name(interrupt_signal()), kExitSignalBase + interrupt_signal());
  if (timer_) finish_summary(failed);
  if (folder_) {
    folder_->remove_partial_files();
    folder_->write_manifest(command_);
  }
  if (log_file_) stop_log_file(log_file_);
}

bool interruption_logged() { return g_interruption_logged; }

void annotate_failed_run(const std::string& error, int exit_code) noexcept {
  if (g_failed_summary.empty()) return;
  try {
    std::ifstream in(g_failed_summary);
    Json j = Json::parse(in, nullptr, false);
    in.close();
    if (!j.is_object()) return;
    j["error"] = error, j["exit_code"] = exit_code;
    write_json_file(partial_path(g_failed_summary), j);
    commit_partial(g_failed_summary);
  } catch (const std::exception& e) {
    spdlog::error("summary.json: {}", e.what());
  }
  g_failed_summary.clear();
}

int not_built(const std::string& command, const std::string& what) {
  spdlog::error("'seamless {}' is not available yet: {}. See README.md, section 'Status'.", command, what);
  return kNotBuilt;
}

}  // namespace seamless::app
