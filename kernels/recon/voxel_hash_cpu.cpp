#include "core/exec_cpu.hpp"
#include "kernels/recon/voxel_hash.inl"
template struct seamless::kernels::VoxelHash<seamless::CpuExec>;
