#include "core/exec_cpu.hpp"
#include "kernels/physics/fluid.inl"
template struct seamless::kernels::Fluid<seamless::CpuExec>;
