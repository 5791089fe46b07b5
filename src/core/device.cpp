#include "core/device.hpp"

#include <spdlog/spdlog.h>

#include <string>

#include "core/cuda_arch.hpp"
#include "core/cuda_check.hpp"
#include "core/error.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

#if SEAMLESS_HAS_CUDA
namespace detail {
cudaError_t probe_kernel_launch();  // core/device_probe.cu

void throw_cuda_error(cudaError_t e, const char* what, const char* file, int line) {
  throw Error(std::string("CUDA error ") + cudaGetErrorName(e) + " (" + cudaGetErrorString(e) + ") in " + what +
              " at " + file + ":" + std::to_string(line));
}
}  // namespace detail
#endif

bool cuda_built() { return SEAMLESS_HAS_CUDA; }

namespace {

// Whether a CUDA GPU is usable, found once: a GPU is present and this build's kernels run on it.
// `problem` says why a GPU that is present is not usable (no kernel image for its architecture,
// a driver too old for the runtime, ...), with what to do about it; it is empty when there is
// simply no GPU.
struct CudaState {
  bool usable = false;
  std::string problem;
};

#if SEAMLESS_HAS_CUDA
std::string cuda_error(cudaError_t e) { return std::string(cudaGetErrorName(e)) + ": " + cudaGetErrorString(e); }

// The architectures the build compiled for (CMake's SEAMLESS_CUDA_ARCH, set on this file only).
#ifndef SEAMLESS_CUDA_ARCHITECTURES
#define SEAMLESS_CUDA_ARCHITECTURES "?"
#endif

std::string unusable_gpu(cudaError_t e) {
  int dev = 0;
  cudaDeviceProp p{};
  std::string gpu = "the GPU", sm;
  if (cudaGetDevice(&dev) == cudaSuccess && cudaGetDeviceProperties(&p, dev) == cudaSuccess) {
    sm = std::to_string(p.major) + std::to_string(p.minor);
    gpu = std::string("the GPU ") + p.name + " (compute capability " + std::to_string(p.major) + "." +
          std::to_string(p.minor) + ", sm_" + sm + ")";
  }
  std::string m = gpu + " cannot run this build's CUDA kernels (" + cuda_error(e) + "); ";
  if (e == cudaErrorNoKernelImageForDevice || e == cudaErrorInvalidDeviceFunction)
    return m +
           "they were compiled for the CUDA architectures \"" SEAMLESS_CUDA_ARCHITECTURES
           "\": rebuild with -DSEAMLESS_CUDA_ARCH=" +
           (sm.empty() ? "<its sm number>" : sm) + " (or -DSEAMLESS_CUDA_ARCH=auto on this machine)";
  if (e == cudaErrorUnsupportedPtxVersion || e == cudaErrorInsufficientDriver)
    return m + "the NVIDIA driver is older than this build's CUDA toolkit needs: update the driver";
  return m + "CUDA's error above says why";
}
#endif

const CudaState& cuda_state() {
  static const CudaState state = [] {
    CudaState s;
#if SEAMLESS_HAS_CUDA
    int n = 0;
    const cudaError_t count = cudaGetDeviceCount(&n);
    if (count != cudaSuccess || n == 0) {
      cudaGetLastError();  // clear the sticky "no device" error
      if (count == cudaErrorInsufficientDriver)
        s.problem = "the NVIDIA driver is older than this build's CUDA toolkit needs (" + cuda_error(count) +
                    "): update the driver";
      return s;
    }
    const cudaError_t probe = detail::probe_kernel_launch();
    if (probe == cudaSuccess) {
      s.usable = true;
      int dev = 0;
      cudaDeviceProp p{};
      if (cudaGetDevice(&dev) == cudaSuccess && cudaGetDeviceProperties(&p, dev) == cudaSuccess)
        if (cuda_arch_match(SEAMLESS_CUDA_ARCHITECTURES, p.major, p.minor) == CudaArchMatch::ptx_only)
          spdlog::info("{}", cuda_arch_advice(SEAMLESS_CUDA_ARCHITECTURES, p.major, p.minor, p.name));
    } else {
      cudaGetLastError();
      s.problem = unusable_gpu(probe);
    }
#endif
    return s;
  }();
  return state;
}

}  // namespace

bool cuda_available() { return cuda_state().usable; }

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
      throw ConfigError(
          "device 'cuda' was asked for, but this build has no CUDA backend "
          "(reconfigure with -DSEAMLESS_CUDA=ON on a machine with nvcc, or use --device cpu)");
    if (!cuda_available())
      throw ConfigError(
          "device 'cuda' was asked for, but " +
          (cuda_state().problem.empty() ? std::string("no CUDA GPU is usable on this machine") : cuda_state().problem) +
          " (or use --device cpu)");
    return Device::CUDA;
  }
  if (name == "auto") {
    if (cuda_available()) return Device::CUDA;
    if (!cuda_state().problem.empty()) {
      static bool said = false;  // once per process, however often the device is resolved
      if (!said) spdlog::warn("device auto: {}; running on the CPU", cuda_state().problem);
      said = true;
    }
    return Device::CPU;
  }
  throw ConfigError("unknown device '" + name + "' (expected cpu, cuda or auto)");
}

const char* device_name(Device d) { return d == Device::CPU ? "cpu" : "cuda"; }

}  // namespace seamless
