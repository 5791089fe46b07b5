#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_fusion.inl"
SEAMLESS_INSTANTIATE_TSDF_FUSION(seamless::CudaExec)
