// Progress of a long loop: a bar redrawn in place on a terminal, a log line every 10% (or at
// least every 30 s) otherwise, so that logs of batch runs stay readable.
#pragma once
#include <chrono>
#include <cstdint>
#include <string>

namespace seamless {

class Progress {
 public:
  Progress(std::string what, std::int64_t total, bool enabled = true);
  ~Progress();
  void update(std::int64_t done, const std::string& status = "");
  void finish();

 private:
  std::string what_;
  std::int64_t total_;
  bool tty_, enabled_, finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_log_;
};

}  // namespace seamless
