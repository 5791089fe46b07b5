#include "core/exec_cpu.hpp"
#include "kernels/physics/integration.inl"
template struct seamless::kernels::Integration<seamless::CpuExec>;
