#include "core/log.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <memory>

namespace seamless {

void init_logging(Verbosity v) {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  console->set_level(v == Verbosity::Quiet ? spdlog::level::warn
                     : v == Verbosity::Verbose ? spdlog::level::debug
                                               : spdlog::level::info);
  auto logger = std::make_shared<spdlog::logger>("seamless", console);
  logger->set_level(spdlog::level::debug);
  logger->set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
}

void log_to_file(const std::string& path) {
  auto file = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path, true);
  file->set_level(spdlog::level::debug);
  file->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] %v");
  spdlog::default_logger()->sinks().push_back(file);
  // Every line reaches the file at once: a run that is killed or fails keeps its log.
  spdlog::default_logger()->flush_on(spdlog::level::trace);
}

}  // namespace seamless
