#include "core/exec_cuda.cuh"
#include "kernels/physics/anisotropy.inl"
template struct seamless::kernels::Anisotropy<seamless::CudaExec>;
