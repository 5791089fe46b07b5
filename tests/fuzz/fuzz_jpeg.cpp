// libFuzzer's entry for the target `jpeg` (fuzz_targets.hpp).
#include "fuzz_targets.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  seamless::fuzz::jpeg(data, size);
  return 0;
}
