#include "core/exec_cpu.hpp"
#include "kernels/physics/grid.inl"
template struct seamless::kernels::NeighbourGrid<seamless::CpuExec>;
