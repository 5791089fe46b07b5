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
#include "app/output_folder.hpp"
#include "app/run_summary.hpp"
#include "config/experiment.hpp"
#include "core/device.hpp"
#include "core/log.hpp"
#include "core/timing.hpp"

namespace seamless::app {

struct CommonOptions {
  std::string command;  // the subcommand's name (summary.json, manifest.txt)
  std::string config;
  std::vector<std::string> sets;  // --set a.b=c, in order
  std::string out;                // --out; default <output.dir>/<config stem>-<time>
  std::string device;             // --device; overrides the config's device
  bool dry_run = false;
  bool force = false;        // --force: clear an output folder that holds an earlier run
  int window_frames = 0;     // run --window-frames: close the window after this many frames
  std::int64_t frames = -1;  // --frames N: as --set frames=N (-1: not given)
};

// The config overrides of the options, in order: every --set, then --device as device=...
std::vector<std::string> overrides(const CommonOptions& o);

// Adds config, --set, --out, --force, --device to a subcommand.
void add_common_options(CLI::App& cmd, CommonOptions& o, bool config_required = true);
// Adds --frames N (the key `frames`; input.max_frames, when also set, is a second limit).
void add_frames_option(CLI::App& cmd, CommonOptions& o);
// A --frames check: a whole number of at least `min` frames; `hint` says what leaving it out does.
CLI::Validator frame_count(std::int64_t min, const std::string& hint);

class RunContext {
 public:
  // Loads and validates the config (throws seamless::ConfigError listing every problem), resolves
  // the device, takes the output folder (app/output_folder.hpp: locked while the run writes; one
  // that holds another run refused unless --force, which removes only that run's files), starts
  // the log file, writes the effective config, marks the run in summary.json as "incomplete" and
  // installs the Ctrl-C / SIGTERM handlers (core/interrupt.hpp) that the frame loops check.
  // The destructor writes summary.json's final status (complete, interrupted or failed) unless the
  // command wrote a full summary itself, removes the *.partial files a failed writer left, and
  // writes manifest.txt.
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

  // Tracking's outcome: when more than output.max_lost_fraction of `frames` were lost, logs an
  // error naming the likely causes and exit_code() becomes kExitLostFrames. `dropped_blocks`: block
  // insertions the volume could not make (a full pool with volume.grow_when_full off): then the
  // model has holes, and that, not the input, is blamed.
  void report_tracking(std::int64_t frames, std::int64_t lost, std::int64_t dropped_blocks = 0);
  // What the subcommand returns when it got to the end: kExitOk or kExitLostFrames.
  // An output that failed after the results were computed (the video encoder): logged as an error;
  // the caller goes on writing the other outputs, and the run exits with kExitError.
  void report_output_failure(const std::string& what);
  int exit_code() const { return exit_code_; }
  // What summary.json says when the command writes no summary of its own (track, reconstruct,
  // simulate, or any failed run): filled as the command goes.
  RunSummary& summary() { return summary_; }

 private:
  void finish_summary(bool failed) noexcept;

  Experiment exp_;
  Device device_;
  std::string out_;
  int window_frames_ = 0;
  int exit_code_ = kExitOk;
  std::unique_ptr<StageTimer> timer_;
  std::shared_ptr<spdlog::sinks::sink> log_file_;
  std::unique_ptr<OutputFolder> folder_;
  RunSummary summary_;
  std::string command_;
  int uncaught_ = 0;  // std::uncaught_exceptions() at construction: more at destruction = failed
};

// The input's ground truth for ATE, when it has one ("" otherwise): the scan writes it beside
// trajectory.txt in the same frame (any source with poses), else a TUM folder's own groundtruth.txt.
std::string groundtruth_path(const RunContext& ctx);

// The paths a run reads (input.path, the camera file, rigid bodies' meshes): --out may not be or
// contain them.
std::vector<std::string> input_paths(const Experiment& e);

// main(): the run that just failed (if any) gets the error message and exit code in its
// summary.json ("status": "failed").
void annotate_failed_run(const std::string& error, int exit_code) noexcept;
// A run already logged that it was stopped by a signal (main then does not say it again).
bool interruption_logged();

// Logs that the subcommand's part of the pipeline is not built yet; returns kNotBuilt (see README).
int not_built(const std::string& command, const std::string& what);

}  // namespace seamless::app
