#include "core/exec_cpu.hpp"
#include "kernels/physics/solver.inl"
SEAMLESS_INSTANTIATE_PHYSICS_SOLVER(seamless::CpuExec)
