#include "core/exec_cuda.cuh"
#include "kernels/recon/voxel_hash.inl"
template struct seamless::kernels::VoxelHash<seamless::CudaExec>;
