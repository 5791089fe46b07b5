#include "core/exec_cuda.cuh"
#include "kernels/recon/rgbd.inl"
SEAMLESS_INSTANTIATE_RGBD(seamless::CudaExec)
