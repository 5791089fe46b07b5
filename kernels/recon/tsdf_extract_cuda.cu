#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_extract.inl"
SEAMLESS_INSTANTIATE_TSDF_EXTRACT(seamless::CudaExec)
