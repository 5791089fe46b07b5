#include "core/exec_cpu.hpp"
#include "kernels/recon/dynamic.inl"
template struct seamless::kernels::Dynamic<seamless::CpuExec>;
