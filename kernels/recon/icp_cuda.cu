#include "core/exec_cuda.cuh"
#include "kernels/recon/icp.inl"
template struct seamless::kernels::Icp<seamless::CudaExec>;
