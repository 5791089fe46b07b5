#include "core/exec_cpu.hpp"
#include "kernels/recon/rgbd.inl"
SEAMLESS_INSTANTIATE_RGBD(seamless::CpuExec)
