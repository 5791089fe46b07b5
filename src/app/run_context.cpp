#include "app/run_context.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <filesystem>

#include "config/config.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"

namespace seamless::app {

namespace fs = std::filesystem;

void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required) {
  auto* c = cmd.add_option("config", o.config, "experiment file (YAML), e.g. configs/demo.yaml");
  if (config_required) c->required()->check(CLI::ExistingFile);
  cmd.add_option("--set", o.sets, "override a config key: --set volume.voxel_size=0.01 (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--out", o.out, "output folder (default: <output.dir>/<config name>-<date-time>)");
  cmd.add_flag("--force", o.force, "write into an output folder that holds an earlier run after clearing it");
  cmd.add_option("--device", o.device, "cpu, cuda or auto (overrides the config's device)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}));
}

std::vector<std::string> overrides(const CommonOptions& o) {
  std::vector<std::string> sets = o.sets;
  if (!o.device.empty()) sets.push_back("device=" + o.device);
  return sets;
}

namespace {
std::string timestamp() {
  std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y%m%d-%H%M%S", std::localtime(&t));
  return buf;
}

}  // namespace

void prepare_output_folder(const std::string& out, bool force, const std::vector<std::string>& marks) {
  std::error_code ec;
  if (fs::exists(out, ec) && !fs::is_directory(out, ec))
    throw UsageError("the output folder " + out + " is a file; give --out a folder");
  if (!fs::is_directory(out, ec)) return;
  std::string found;
  for (const std::string& m : marks)
    if (fs::exists(fs::path(out) / m)) found += (found.empty() ? "" : ", ") + m;
  if (found.empty()) return;
  if (!force)
    throw UsageError("the output folder " + out + " holds an earlier run (" + found +
                     "); choose another --out, or add "
                     "--force to clear it first");
  std::vector<fs::path> entries;
  for (const auto& entry : fs::directory_iterator(out)) entries.push_back(entry.path());
  for (const fs::path& p : entries) fs::remove_all(p, ec);
  if (!fs::is_empty(out, ec)) throw Error("--force: could not clear the output folder " + out);
  spdlog::info("--force: cleared {} entries of the earlier run in {}", entries.size(), out);
}

RunContext::RunContext(const CommonOptions& o) : RunContext(o, load_experiment(o.config, overrides(o))) {}

RunContext::RunContext(const CommonOptions& o, Experiment e) : exp_(std::move(e)), window_frames_(o.window_frames) {
  device_ = resolve_device(exp_.device);

  out_ = o.out.empty() ? default_out_dir(exp_, o.config) : o.out;
  prepare_output_folder(out_, o.force, {"config.yaml", "log.txt"});  // what every run writes first
  std::error_code ec;
  fs::create_directories(out_, ec);
  if (ec) throw Error("cannot create the output folder " + out_ + ": " + ec.message());
  log_file_ = log_to_file(out_path("log.txt"));
  if (exp_.output.write_config) write_effective_config(exp_, out_path("config.yaml"));
  timer_ = std::make_unique<StageTimer>(device_);
  install_interrupt_handlers();

  std::string gpu = device_ == Device::CUDA ? " (" + cuda_device_description() + ")" : "";
  spdlog::info("experiment '{}' from {}, device {}{}, output {}", exp_.name, o.config, device_name(device_), gpu, out_);
}

std::string default_out_dir(const Experiment& e, const std::string& config) {
  return e.output.dir + "/" + fs::path(config).stem().string() + "-" + timestamp();
}

std::unique_ptr<FrameSource> RunContext::open_source() {
  if (!source_given_) return make_source(exp_.input, device_);
  if (!given_source_)
    throw UsageError(
        "the frames given to this run were read already, and this run reads its input twice (render.camera: "
        "recorded replays it): give the frames through input.source instead");
  return std::move(given_source_);
}

void RunContext::set_source(std::unique_ptr<FrameSource> source) {
  given_source_ = std::move(source);
  source_given_ = true;
}

void RunContext::report_tracking(std::int64_t frames, std::int64_t lost) {
  if (frames <= 0) return;
  const double fraction = static_cast<double>(lost) / static_cast<double>(frames);
  if (fraction <= exp_.output.max_lost_fraction) return;
  exit_code_ = kExitLostFrames;
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

RunContext::~RunContext() {
  if (exp_.output.write_timings && timer_ && !timer_->rows().empty()) {
    try {
      timer_->write_csv(out_path("timings.csv"));
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
    }
  }
  if (log_file_) stop_log_file(log_file_);
}

int not_built(const std::string& command, const std::string& what) {
  spdlog::error("'seamless {}' is not available yet: {}. See README.md, section 'Status'.", command, what);
  return kNotBuilt;
}

}  // namespace seamless::app
