#include "core/interrupt.hpp"

#include <spdlog/spdlog.h>

#include <atomic>
#include <csignal>

namespace seamless {

namespace {
volatile std::sig_atomic_t g_signal = 0;
std::atomic<bool> g_reported{false};

extern "C" void on_signal(int sig) { g_signal = sig; }
}  // namespace

void install_interrupt_handlers() {
  g_signal = 0;
  g_reported = false;
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  sa.sa_flags = SA_RESETHAND;  // the second signal gets the default action: the process stops
  sigaction(SIGINT, &sa, nullptr);
  sigaction(SIGTERM, &sa, nullptr);
}

bool interrupted() {
  const int sig = g_signal;
  if (sig == 0) return false;
  if (!g_reported.exchange(true))
    spdlog::warn("{} received: finishing the current frame, then writing the outputs (send it again to stop at once)",
                 sig == SIGINT    ? "SIGINT (Ctrl-C)"
                 : sig == SIGTERM ? "SIGTERM"
                                  : "a signal");
  return true;
}

int interrupt_signal() { return g_signal; }

}  // namespace seamless
