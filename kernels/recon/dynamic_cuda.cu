#include "core/exec_cuda.cuh"
#include "kernels/recon/dynamic.inl"
SEAMLESS_INSTANTIATE_DYNAMIC(seamless::CudaExec)
