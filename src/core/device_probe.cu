// One trivial kernel, launched once when seamless first asks whether the GPU is usable
// (core/device.cpp): the CUDA runtime loads this binary's kernel image for the device (or
// JIT-compiles its PTX) at the first launch, so a card the build has no code for fails here with
// cudaErrorNoKernelImageForDevice, where device `auto` can still choose the CPU, instead of in the
// middle of a run. Every .cu of the build is compiled for the same architectures
// (CMAKE_CUDA_ARCHITECTURES), so this kernel stands for all of them.
#include <cuda_runtime_api.h>

namespace seamless::detail {

namespace {
__global__ void probe_kernel(int* out) { *out = 1; }
}  // namespace

cudaError_t probe_kernel_launch() {
  int* d = nullptr;
  cudaError_t e = cudaMalloc(&d, sizeof(int));
  if (e != cudaSuccess) return e;
  probe_kernel<<<1, 1>>>(d);
  e = cudaGetLastError();
  if (e == cudaSuccess) e = cudaDeviceSynchronize();
  int h = 0;
  if (e == cudaSuccess) e = cudaMemcpy(&h, d, sizeof(int), cudaMemcpyDeviceToHost);
  cudaFree(d);
  if (e == cudaSuccess && h != 1) e = cudaErrorLaunchFailure;  // the kernel did not run
  return e;
}

}  // namespace seamless::detail
