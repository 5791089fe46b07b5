#include "core/exec_cpu.hpp"
#include "kernels/recon/rgbd.inl"
template struct seamless::kernels::Rgbd<seamless::CpuExec>;
