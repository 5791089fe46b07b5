// libFuzzer's entry for the target `png` (fuzz_targets.hpp).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  seamless::fuzz::png(data, size);
  return 0;
}
