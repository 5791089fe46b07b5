#include "core/progress.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

namespace seamless {

namespace {

std::string duration_text(double s) {
  char b[48];
  const long long t = std::llround(s);
  if (s < 9.95) std::snprintf(b, sizeof b, "%.1f s", s);
  else if (t < 60) std::snprintf(b, sizeof b, "%lld s", t);
  else if (t < 3600) std::snprintf(b, sizeof b, "%lld:%02lld", t / 60, t % 60);
  else std::snprintf(b, sizeof b, "%lld:%02lld:%02lld", t / 3600, t / 60 % 60, t % 60);
  return b;
}

ProgressObserver& observer() {
  static ProgressObserver o;
  return o;
}

}  // namespace

void set_progress_observer(ProgressObserver o) { observer() = std::move(o); }

std::string progress_rate_text(std::int64_t done, std::int64_t total, double secs, const std::string& unit) {
  if (done <= 0 || !(secs > 0)) return "";
  const double rate = static_cast<double>(done) / secs;
  char b[48];
  std::snprintf(b, sizeof b, rate < 10 ? "%.2f %s" : "%.1f %s", rate, unit.c_str());
  std::string text = b;
  if (total > 0 && done <= total) text += ", " + duration_text(static_cast<double>(total - done) / rate) + " left";
  return text;
}

Progress::Progress(std::string what, std::int64_t total, bool enabled, std::string unit)
    : what_(std::move(what)), unit_(std::move(unit)), total_(total), tty_(isatty(fileno(stderr)) != 0),
      enabled_(enabled && spdlog::default_logger()->should_log(spdlog::level::info)),
      start_(std::chrono::steady_clock::now()), last_log_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::int64_t done, const std::string& status) {
  if (observer()) observer()(what_, done, total_, status);
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  double secs = std::chrono::duration<double>(now - start_).count();
  double frac = total_ > 0 ? static_cast<double>(done) / total_ : 0.0;
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = static_cast<int>(frac * kWidth);
    // \033[K clears what a longer earlier line left to the right.
    std::fprintf(stderr, "\r%s [%.*s%*s] %lld/%lld %.1fs %s %s\033[K", what_.c_str(), filled,
                 "##############################", kWidth - filled, "", static_cast<long long>(done),
                 static_cast<long long>(total_), secs, progress_rate_text(done, total_, secs, unit_).c_str(),
                 status.c_str());
    std::fflush(stderr);
    return;
  }
  int decile = static_cast<int>(frac * 10);
  if (decile > last_decile_ || now - last_log_ > std::chrono::seconds(30)) {
    last_decile_ = decile;
    last_log_ = now;
    const std::string rate = progress_rate_text(done, total_, secs, unit_);
    spdlog::info("{}: {}/{} ({:.0f}%) after {:.1f} s{}{} {}", what_, done, total_, 100 * frac, secs,
                 rate.empty() ? "" : ", ", rate, status);
  }
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (enabled_ && tty_) std::fprintf(stderr, "\n");
}

}  // namespace seamless
