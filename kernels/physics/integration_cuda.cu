#include "core/exec_cuda.cuh"
#include "kernels/physics/integration.inl"
template struct seamless::kernels::Integration<seamless::CudaExec>;
