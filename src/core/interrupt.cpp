#include "core/interrupt.hpp"

#include <spdlog/spdlog.h>

#include <unistd.h>

#include <atomic>
#include <csignal>

namespace seamless {

namespace {
volatile std::sig_atomic_t g_signal = 0;
std::atomic<bool> g_reported{false};

// The first signal is recorded; the second says so and ends the process at once, by that signal
// (write, signal and raise are async-signal-safe). The run's summary.json then still says
// "incomplete", as RunContext wrote it at the start.
extern "C" void on_signal(int sig) {
  if (g_signal == 0) {
    g_signal = sig;
    return;
  }
  static const char msg[] =
      "\nseamless: second signal: stopping at once; the output folder is incomplete (summary.json: \"incomplete\", "
      "*.partial files)\n";
  [[maybe_unused]] const ssize_t n = write(2, msg, sizeof msg - 1);
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}
}  // namespace

void install_interrupt_handlers() {
  g_signal = 0;
  g_reported = false;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = 0;  // the second signal also comes to on_signal, which then stops the process
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupted() {
  const int sig = g_signal;
  if (sig == 0) return false;
  if (!g_reported.exchange(true))
    spdlog::warn("{} received: finishing the current frame, then writing the outputs (send it again to stop at once)",
                 sig == SIGINT ? "SIGINT (Ctrl-C)" : signal_name(sig));
  return true;
}

int interrupt_signal() { return g_signal; }

const char* signal_name(int sig) {
  return sig == SIGINT ? "SIGINT" : sig == SIGTERM ? "SIGTERM" : sig == 0 ? "" : "a signal";
}

}  // namespace seamless
