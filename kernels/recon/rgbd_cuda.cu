#include "core/exec_cuda.cuh"
#include "kernels/recon/rgbd.inl"
template struct seamless::kernels::Rgbd<seamless::CudaExec>;
