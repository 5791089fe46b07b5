// Every CUDA runtime call and launch is checked; a failure throws seamless::Error naming the call,
// the file and line, and CUDA's own message.
#pragma once
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_CUDA
#include <cuda_runtime_api.h>

#include <string>

#include "core/error.hpp"

namespace seamless::detail {
[[noreturn]] void throw_cuda_error(cudaError_t e, const char* what, const char* file, int line);
}  // namespace seamless::detail

#define SEAMLESS_CUDA_CHECK(call)                                                                                     \
  do {                                                                                                                \
    cudaError_t seamless_err_ = (call);                                                                               \
    if (seamless_err_ != cudaSuccess) ::seamless::detail::throw_cuda_error(seamless_err_, #call, __FILE__, __LINE__); \
  } while (0)

// After a kernel launch: catches launch-configuration errors at once.
#define SEAMLESS_CUDA_CHECK_LAUNCH(name) SEAMLESS_CUDA_CHECK(cudaPeekAtLastError())
#endif
