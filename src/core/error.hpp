// One exception type for errors a user can act on: the message names the problem and the fix.
// Two subclasses say whose fault it is, so that the command's exit code tells a script what
// went wrong without parsing the message (README, "Exit codes and interrupted runs").
#pragma once
#include <stdexcept>
#include <string>

namespace seamless {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// The experiment asks for something invalid or impossible: a bad key or value in the file or a
// --set, a tracker or device this build or machine does not have. Nothing was run.
struct ConfigError : Error {
  using Error::Error;
};

// The data read is missing, unreadable or malformed: a TUM list, a PNG, a trajectory, a mesh,
// a Kinect that does not deliver.
struct InputError : Error {
  using Error::Error;
};

// The command line asks for something that cannot be done as given (an output folder that holds
// another run, without --force).
struct UsageError : Error {
  using Error::Error;
};

}  // namespace seamless
