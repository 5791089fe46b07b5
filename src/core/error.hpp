// One exception type for errors a user can act on: the message names the problem and the fix.
#pragma once
#include <stdexcept>
#include <string>

namespace seamless {

struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

}  // namespace seamless
