#include "core/exec_cpu.hpp"
#include "kernels/recon/icp.inl"
template struct seamless::kernels::Icp<seamless::CpuExec>;
