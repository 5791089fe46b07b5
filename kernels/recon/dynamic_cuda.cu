#include "core/exec_cuda.cuh"
#include "kernels/recon/dynamic.inl"
template struct seamless::kernels::Dynamic<seamless::CudaExec>;
