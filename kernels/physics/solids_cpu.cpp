#include "core/exec_cpu.hpp"
#include "kernels/physics/solids.inl"
template struct seamless::kernels::Solids<seamless::CpuExec>;
