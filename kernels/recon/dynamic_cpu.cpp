#include "core/exec_cpu.hpp"
#include "kernels/recon/dynamic.inl"
SEAMLESS_INSTANTIATE_DYNAMIC(seamless::CpuExec)
