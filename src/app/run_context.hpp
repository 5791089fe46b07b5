// What every subcommand that runs an experiment shares: the common options, the loaded and
// validated config, the resolved device, and the run's own output folder (effective config, log,
// timings).
#pragma once
#include <CLI/CLI.hpp>

#include <memory>
#include <string>
#include <vector>

#include "config/experiment.hpp"
#include "core/device.hpp"
#include "core/timing.hpp"

namespace seamless::app {

struct CommonOptions {
  std::string config;
  std::vector<std::string> sets;  // --set a.b=c, in order
  std::string out;                // --out; default <output.dir>/<config stem>-<time>
  std::string device;             // --device; overrides the config's device
  bool dry_run = false;
  int window_frames = 0;          // run --window-frames: close the window after this many frames
};

// The config overrides of the options, in order: every --set, then --device as device=...
std::vector<std::string> overrides(const CommonOptions& o);

// Adds config, --set, --out, --device (and --dry-run when asked) to a subcommand.
void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required = true);

class RunContext {
 public:
  // Loads and validates the config (throws seamless::Error naming file:line and key), resolves the
  // device, creates the output folder, starts the log file and writes the effective config.
  explicit RunContext(const CommonOptions& o);
  ~RunContext();

  const Experiment& experiment() const { return exp_; }
  Experiment& experiment() { return exp_; }
  Device device() const { return device_; }
  const std::string& out_dir() const { return out_; }
  std::string out_path(const std::string& file) const { return out_ + "/" + file; }
  StageTimer& timer() { return *timer_; }
  // render.mode window: close the window after this many frames (0: when the user closes it).
  int window_frames() const { return window_frames_; }

 private:
  Experiment exp_;
  Device device_;
  std::string out_;
  int window_frames_ = 0;
  std::unique_ptr<StageTimer> timer_;
};

// Exit code of a subcommand whose part of the pipeline is not built yet (see README).
constexpr int kNotBuilt = 3;
int not_built(const std::string& command, const std::string& what);

}  // namespace seamless::app
