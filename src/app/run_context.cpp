#include "app/run_context.hpp"

#include <spdlog/spdlog.h>

#include <chrono>
#include <ctime>
#include <filesystem>

#include "config/config.hpp"
#include "core/error.hpp"
#include "core/log.hpp"

namespace seamless::app {

namespace fs = std::filesystem;

void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required) {
  auto* c = cmd.add_option("config", o.config, "experiment file (YAML), e.g. configs/demo.yaml");
  if (config_required) c->required()->check(CLI::ExistingFile);
  cmd.add_option("--set", o.sets, "override a config key: --set volume.voxel_size=0.01 (repeatable)")
      ->allow_extra_args(false);
  cmd.add_option("--out", o.out, "output folder (default: <output.dir>/<config name>-<date-time>)");
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

RunContext::RunContext(const CommonOptions& o) : window_frames_(o.window_frames) {
  exp_ = load_experiment(o.config, overrides(o));
  device_ = resolve_device(exp_.device);

  out_ = o.out.empty() ? exp_.output.dir + "/" + fs::path(o.config).stem().string() + "-" + timestamp() : o.out;
  std::error_code ec;
  fs::create_directories(out_, ec);
  if (ec) throw Error("cannot create the output folder " + out_ + ": " + ec.message());
  log_to_file(out_path("log.txt"));
  if (exp_.output.write_config) write_effective_config(exp_, out_path("config.yaml"));
  timer_ = std::make_unique<StageTimer>(device_);

  std::string gpu = device_ == Device::CUDA ? " (" + cuda_device_description() + ")" : "";
  spdlog::info("experiment '{}' from {}, device {}{}, output {}", exp_.name, o.config, device_name(device_), gpu,
               out_);
}

RunContext::~RunContext() {
  if (!exp_.output.write_timings || !timer_ || timer_->rows().empty()) return;
  try {
    timer_->write_csv(out_path("timings.csv"));
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
  }
}

int not_built(const std::string& command, const std::string& what) {
  spdlog::error("'seamless {}' is not available yet: {}. See README.md, section 'Status'.", command, what);
  return kNotBuilt;
}

}  // namespace seamless::app
