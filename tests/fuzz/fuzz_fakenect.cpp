// libFuzzer's entry for the target `fakenect` (fuzz_targets.hpp).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  seamless::fuzz::fakenect(data, size);
  return 0;
}
