#include "core/exec_cpu.hpp"
#include "kernels/recon/icp.inl"
SEAMLESS_INSTANTIATE_ICP(seamless::CpuExec)
