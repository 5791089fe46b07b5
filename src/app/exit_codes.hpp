// The exit codes of the `seamless` command (README, "Exit codes and interrupted runs"; --help).
// Scripts and sweeps tell a finished run from a failed one by these, never by parsing messages.
#pragma once

namespace seamless::app {

constexpr int kExitOk = 0;
constexpr int kExitError = 1;   // any other failure (cannot write an output, a GPU error, ...)
constexpr int kExitUsage = 2;   // bad command line; an --out that holds another run, is in use, or cannot be written
constexpr int kNotBuilt = 3;    // the asked-for part of the pipeline is not built
constexpr int kExitConfig = 4;  // the experiment (file or --set) is invalid or asks for what is not there
constexpr int kExitInput = 5;   // input data missing, unreadable or malformed
constexpr int kExitLostFrames = 6;  // the run finished, but tracking lost more than output.max_lost_fraction
// Interrupted by a signal: 128 + the signal number (130 Ctrl-C, 143 SIGTERM), the outputs written.
constexpr int kExitSignalBase = 128;

// The codes as --help shows them.
constexpr const char* kExitCodesHelp =
    "Exit codes: 0 success; 1 error; 2 bad usage (--out holds another run: add --force; --out is in use, not\n"
    "writable or holds the input); 3 part not built; 4 config error; 5 input error (missing or corrupt data);\n"
    "6 tracking lost more than output.max_lost_fraction of the frames (outputs written); 130 / 143 stopped by\n"
    "Ctrl-C / SIGTERM after writing the outputs. summary.json \"status\": complete, interrupted, failed, or\n"
    "incomplete (still running, or stopped at once by a second signal).";

}  // namespace seamless::app
