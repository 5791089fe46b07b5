// Non-template parts of the CUDA executor.
#include "core/exec_cuda.cuh"

namespace seamless {

void CudaExec::synchronize() const { SEAMLESS_CUDA_CHECK(cudaDeviceSynchronize()); }

namespace cuda_detail {

void* scratch(std::size_t bytes) {
  static void* ptr = nullptr;
  static std::size_t size = 0;
  if (bytes > size) {
    if (ptr) SEAMLESS_CUDA_CHECK(cudaFree(ptr));
    size = bytes + bytes / 2;
    SEAMLESS_CUDA_CHECK(cudaMalloc(&ptr, size));
  }
  return ptr;
}

int multiprocessors() {
  static int count = [] {
    int dev = 0, n = 0;
    SEAMLESS_CUDA_CHECK(cudaGetDevice(&dev));
    SEAMLESS_CUDA_CHECK(cudaDeviceGetAttribute(&n, cudaDevAttrMultiProcessorCount, dev));
    return n;
  }();
  return count;
}

}  // namespace cuda_detail
}  // namespace seamless
