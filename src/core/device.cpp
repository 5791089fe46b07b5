#include "core/device.hpp"

#include <string>

#include "core/cuda_check.hpp"
#include "core/error.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

#if SEAMLESS_HAS_CUDA
namespace detail {
void throw_cuda_error(cudaError_t e, const char* what, const char* file, int line) {
  throw Error(std::string("CUDA error ") + cudaGetErrorName(e) + " (" + cudaGetErrorString(e) + ") in " + what +
              " at " + file + ":" + std::to_string(line));
}
}  // namespace detail
#endif

bool cuda_built() { return SEAMLESS_HAS_CUDA; }

bool cuda_available() {
#if SEAMLESS_HAS_CUDA
  int n = 0;
  if (cudaGetDeviceCount(&n) != cudaSuccess) {
    cudaGetLastError();  // clear the sticky "no device" error
    return false;
  }
  return n > 0;
#else
  return false;
#endif
}

std::string cuda_device_description() {
#if SEAMLESS_HAS_CUDA
  if (!cuda_available()) return "";
  int dev = 0;
  cudaDeviceProp p{};
  SEAMLESS_CUDA_CHECK(cudaGetDevice(&dev));
  SEAMLESS_CUDA_CHECK(cudaGetDeviceProperties(&p, dev));
  return std::string(p.name) + " (sm_" + std::to_string(p.major) + std::to_string(p.minor) + ", " +
         std::to_string(p.totalGlobalMem >> 30) + " GiB)";
#else
  return "";
#endif
}

Device resolve_device(const std::string& name) {
  if (name == "cpu") return Device::CPU;
  if (name == "cuda") {
    if (!cuda_built())
      throw ConfigError("device 'cuda' was asked for, but this build has no CUDA backend "
                  "(reconfigure with -DSEAMLESS_CUDA=ON on a machine with nvcc, or use --device cpu)");
    if (!cuda_available())
      throw ConfigError("device 'cuda' was asked for, but no CUDA GPU is usable on this machine (use --device cpu)");
    return Device::CUDA;
  }
  if (name == "auto") return cuda_available() ? Device::CUDA : Device::CPU;
  throw ConfigError("unknown device '" + name + "' (expected cpu, cuda or auto)");
}

const char* device_name(Device d) { return d == Device::CPU ? "cpu" : "cuda"; }

}  // namespace seamless
