// Logging through spdlog: one console sink (level from --quiet/--verbose) and, once a run has an
// output folder, a file sink there.
#pragma once
#include <spdlog/spdlog.h>

#include <string>

namespace seamless {

enum class Verbosity { Quiet, Normal, Verbose };
void init_logging(Verbosity v);
void log_to_file(const std::string& path);  // adds a file sink (all levels)

}  // namespace seamless
