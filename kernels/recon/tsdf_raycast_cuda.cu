#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_raycast.inl"
SEAMLESS_INSTANTIATE_TSDF_RAYCAST(seamless::CudaExec)
