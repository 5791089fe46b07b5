// Progress of a long loop: a bar redrawn in place on a terminal, a log line every 10% (or at
// least every 30 s) otherwise, so that logs of batch runs stay readable. Both say the rate
// (frames per second, or steps) and the time left at that rate.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace seamless {

// "12.5 fps, 4.8 s left" after `done` of `total` items in `secs` seconds, `unit` naming the rate
// ("fps", "steps/s"). The time left assumes the rate so far holds; it reads "1:05" from a minute
// and "1:02:03" from an hour. Nothing is said of a rate before anything is done (or no time has
// passed), nor of the time left without a total.
std::string progress_rate_text(std::int64_t done, std::int64_t total, double secs, const std::string& unit = "fps");

// A program that embeds seamless (the Python module) follows progress here: every update of every
// Progress calls it (what, done, total, status), on the thread of the loop, besides the bar or the
// log lines. Empty (the default): none.
using ProgressObserver =
    std::function<void(const std::string& what, std::int64_t done, std::int64_t total, const std::string& status)>;
void set_progress_observer(ProgressObserver observer);

class Progress {
 public:
  Progress(std::string what, std::int64_t total, bool enabled = true, std::string unit = "fps");
  ~Progress();
  void update(std::int64_t done, const std::string& status = "");
  void finish();

 private:
  std::string what_, unit_;
  std::int64_t total_;
  bool tty_, enabled_, finished_ = false;
  int last_decile_ = -1;
  std::chrono::steady_clock::time_point start_, last_log_;
};

}  // namespace seamless
