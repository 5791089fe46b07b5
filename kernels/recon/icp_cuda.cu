#include "core/exec_cuda.cuh"
#include "kernels/recon/icp.inl"
SEAMLESS_INSTANTIATE_ICP(seamless::CudaExec)
