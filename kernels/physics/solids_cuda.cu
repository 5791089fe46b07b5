#include "core/exec_cuda.cuh"
#include "kernels/physics/solids.inl"
template struct seamless::kernels::Solids<seamless::CudaExec>;
