#include "core/exec_cuda.cuh"
#include "kernels/recon/dynamic.inl"
template struct seamless::kernels::Dynamic<seamless::CudaExec>;
template struct seamless::kernels::DynamicSpace<seamless::CudaExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::DynamicSpace<seamless::CudaExec, seamless::kernels::DenseAccess>;
