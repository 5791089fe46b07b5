#include "core/exec_cpu.hpp"
#include "kernels/physics/anisotropy.inl"
template struct seamless::kernels::Anisotropy<seamless::CpuExec>;
