// libFuzzer's entry for the target `frames` (fuzz_targets.hpp).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  seamless::fuzz::frames(data, size);
  return 0;
}
