#include "core/exec_cuda.cuh"
#include "kernels/physics/fluid.inl"
template struct seamless::kernels::Fluid<seamless::CudaExec>;
