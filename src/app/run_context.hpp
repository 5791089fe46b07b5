// What every subcommand that runs an experiment shares: the common options, the loaded and
// validated config, the resolved device, and the run's own output folder (effective config, log,
// timings).
#pragma once
#include <CLI/CLI.hpp>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "app/exit_codes.hpp"
#include "config/experiment.hpp"
#include "core/device.hpp"
#include "core/log.hpp"
#include "core/timing.hpp"
#include "io/frame_source.hpp"

namespace seamless::app {

struct CommonOptions {
  std::string config;
  std::vector<std::string> sets;  // --set a.b=c, in order
  std::string out;                // --out; default <output.dir>/<config stem>-<time>
  std::string device;             // --device; overrides the config's device
  bool dry_run = false;
  bool force = false;     // --force: clear an output folder that holds an earlier run
  int window_frames = 0;  // run --window-frames: close the window after this many frames
};

// The config overrides of the options, in order: every --set, then --device as device=...
std::vector<std::string> overrides(const CommonOptions& o);

// Adds config, --set, --out, --force, --device to a subcommand.
void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required = true);

class RunContext {
 public:
  // Loads and validates the config (throws seamless::ConfigError naming file:line and key), resolves
  // the device, creates the output folder (refusing one that holds another run unless --force, which
  // clears it), starts the log file, writes the effective config and installs the Ctrl-C / SIGTERM
  // handlers (core/interrupt.hpp) that the frame loops check.
  explicit RunContext(const CommonOptions& o);
  // The same with an experiment the caller loaded (and adjusted) itself; o.config only names it.
  RunContext(const CommonOptions& o, Experiment e);
  ~RunContext();
  RunContext(const RunContext&) = delete;
  RunContext& operator=(const RunContext&) = delete;

  const Experiment& experiment() const { return exp_; }
  Experiment& experiment() { return exp_; }
  Device device() const { return device_; }
  const std::string& out_dir() const { return out_; }
  std::string out_path(const std::string& file) const { return out_ + "/" + file; }
  StageTimer& timer() { return *timer_; }
  // render.mode window: close the window after this many frames (0: when the user closes it).
  int window_frames() const { return window_frames_; }

  // The input: the source set_source() gave (once: a stream cannot be read twice), else a new
  // source of the config's input section. Throws seamless::UsageError when the given source was
  // taken already (a replay reads the input a second time).
  std::unique_ptr<FrameSource> open_source();
  // Frames from the caller (the Python module's frame source) instead of input.source.
  void set_source(std::unique_ptr<FrameSource> source);

  // Tracking's outcome: when more than output.max_lost_fraction of `frames` were lost, logs an
  // error naming the likely causes and exit_code() becomes kExitLostFrames.
  void report_tracking(std::int64_t frames, std::int64_t lost);
  // What the subcommand returns when it got to the end: kExitOk or kExitLostFrames.
  // An output that failed after the results were computed (the video encoder): logged as an error;
  // the caller goes on writing the other outputs, and the run exits with kExitError.
  void report_output_failure(const std::string& what);
  int exit_code() const { return exit_code_; }

 private:
  Experiment exp_;
  Device device_;
  std::string out_;
  int window_frames_ = 0;
  int exit_code_ = kExitOk;
  std::unique_ptr<StageTimer> timer_;
  std::shared_ptr<spdlog::sinks::sink> log_file_;
  std::unique_ptr<FrameSource> given_source_;
  bool source_given_ = false;
};

// The output folder when --out is not given: <output.dir>/<config file's stem>-<date-time>.
std::string default_out_dir(const Experiment& e, const std::string& config);

// An output folder holds one run's files only: when `out` holds any of `marks` (files an earlier
// run wrote), throws seamless::UsageError naming them, or with `force` removes everything in it.
void prepare_output_folder(const std::string& out, bool force, const std::vector<std::string>& marks);

// Logs that the subcommand's part of the pipeline is not built yet; returns kNotBuilt (see README).
int not_built(const std::string& command, const std::string& what);

}  // namespace seamless::app
