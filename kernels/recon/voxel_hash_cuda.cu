#include "core/exec_cuda.cuh"
#include "kernels/recon/voxel_hash.inl"
SEAMLESS_INSTANTIATE_VOXEL_HASH(seamless::CudaExec)
