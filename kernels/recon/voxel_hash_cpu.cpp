#include "core/exec_cpu.hpp"
#include "kernels/recon/voxel_hash.inl"
SEAMLESS_INSTANTIATE_VOXEL_HASH(seamless::CpuExec)
