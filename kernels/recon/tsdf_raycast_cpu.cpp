#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_raycast.inl"
SEAMLESS_INSTANTIATE_TSDF_RAYCAST(seamless::CpuExec)
