#include "core/progress.hpp"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>

namespace seamless {

Progress::Progress(std::string what, std::int64_t total, bool enabled)
    : what_(std::move(what)),
      total_(total),
      tty_(isatty(fileno(stderr)) != 0),
      enabled_(enabled && spdlog::default_logger()->should_log(spdlog::level::info)),
      start_(std::chrono::steady_clock::now()),
      last_log_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::int64_t done, const std::string& status) {
  if (!enabled_) return;
  auto now = std::chrono::steady_clock::now();
  double secs = std::chrono::duration<double>(now - start_).count();
  double frac = total_ > 0 ? static_cast<double>(done) / total_ : 0.0;
  if (tty_) {
    constexpr int kWidth = 30;
    int filled = static_cast<int>(frac * kWidth);
    std::fprintf(stderr, "\r%s [%.*s%*s] %lld/%lld %.1fs %s", what_.c_str(), filled,
                 "##############################", kWidth - filled, "", static_cast<long long>(done),
                 static_cast<long long>(total_), secs, status.c_str());
    std::fflush(stderr);
    return;
  }
  int decile = static_cast<int>(frac * 10);
  if (decile > last_decile_ || now - last_log_ > std::chrono::seconds(30)) {
    last_decile_ = decile;
    last_log_ = now;
    spdlog::info("{}: {}/{} ({:.0f}%) after {:.1f} s {}", what_, done, total_, 100 * frac, secs, status);
  }
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  if (enabled_ && tty_) std::fprintf(stderr, "\n");
}

}  // namespace seamless
