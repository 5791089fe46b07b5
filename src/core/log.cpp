#include "core/log.hpp"

#include <spdlog/sinks/basic_file_sink.h>
#include <spdlog/sinks/stdout_color_sinks.h>

#include <algorithm>
#include <memory>

namespace seamless {

void init_logging(Verbosity v) {
  auto console = std::make_shared<spdlog::sinks::stderr_color_sink_mt>();
  console->set_level(v == Verbosity::Quiet     ? spdlog::level::warn
                     : v == Verbosity::Verbose ? spdlog::level::debug
                                               : spdlog::level::info);
  auto logger = std::make_shared<spdlog::logger>("seamless", console);
  logger->set_level(spdlog::level::debug);
  logger->set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");
  spdlog::set_default_logger(logger);
}

std::shared_ptr<spdlog::sinks::sink> log_to_file(const std::string& path) {
  auto file = std::make_shared<spdlog::sinks::basic_file_sink_mt>(path, true);
  file->set_level(spdlog::level::debug);
  file->set_pattern("[%Y-%m-%d %H:%M:%S.%e] [%l] %v");
  spdlog::default_logger()->sinks().push_back(file);
  // Every line reaches the file at once: a run that is killed or fails keeps its log.
  spdlog::default_logger()->flush_on(spdlog::level::trace);
  return file;
}

void stop_log_file(const std::shared_ptr<spdlog::sinks::sink>& sink) {
  auto& sinks = spdlog::default_logger()->sinks();
  sinks.erase(std::remove(sinks.begin(), sinks.end(), sink), sinks.end());
}

}  // namespace seamless
