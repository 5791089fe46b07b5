#include "core/exec_cuda.cuh"
#include "kernels/physics/grid.inl"
template struct seamless::kernels::NeighbourGrid<seamless::CudaExec>;
