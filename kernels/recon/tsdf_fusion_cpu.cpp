#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_fusion.inl"
SEAMLESS_INSTANTIATE_TSDF_FUSION(seamless::CpuExec)
