// Logging through spdlog: one console sink (level from --quiet/--verbose) and, once a run has an
// output folder, a file sink there.
#pragma once
#include <spdlog/spdlog.h>

#include <memory>
#include <string>

namespace seamless {

enum class Verbosity { Quiet, Normal, Verbose };
void init_logging(Verbosity v);
// Adds a file sink (all levels); stop_log_file removes it again (a process that runs several runs,
// `seamless bench pipeline --reps`, must not write one run's log into the last one's file).
std::shared_ptr<spdlog::sinks::sink> log_to_file(const std::string& path);
void stop_log_file(const std::shared_ptr<spdlog::sinks::sink>& sink);

}  // namespace seamless
