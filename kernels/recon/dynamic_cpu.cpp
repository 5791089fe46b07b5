#include "core/exec_cpu.hpp"
#include "kernels/recon/dynamic.inl"
template struct seamless::kernels::Dynamic<seamless::CpuExec>;
template struct seamless::kernels::DynamicSpace<seamless::CpuExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::DynamicSpace<seamless::CpuExec, seamless::kernels::DenseAccess>;
