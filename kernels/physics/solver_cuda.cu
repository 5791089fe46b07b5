#include "core/exec_cuda.cuh"
#include "kernels/physics/solver.inl"
SEAMLESS_INSTANTIATE_PHYSICS_SOLVER(seamless::CudaExec)
