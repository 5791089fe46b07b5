// Ctrl-C (SIGINT) and SIGTERM during a run. The handler only records the signal (nothing else is
// safe inside a signal handler); the frame loops ask interrupted() between frames, finish the
// frame they are in and write their outputs, and the command exits with 128 + the signal number
// (130 for Ctrl-C, 143 for SIGTERM, as shells report them). A second signal, while the outputs
// are being written, stops the process at once (killed by that signal), saying so on stderr.
// README, section "Exit codes and interrupted runs".
#pragma once

namespace seamless {

// Installs the handlers for SIGINT and SIGTERM (again after a signal was seen: a new run). Only
// commands whose loops check interrupted() install them; the others keep the default (stop at once).
void install_interrupt_handlers();

// True once a signal arrived. The first call that sees it logs what happens next.
bool interrupted();

// The signal that arrived (SIGINT, SIGTERM), 0 when none.
int interrupt_signal();

// "SIGINT", "SIGTERM" (summary.json, log lines); "" for 0.
const char* signal_name(int sig);

}  // namespace seamless
