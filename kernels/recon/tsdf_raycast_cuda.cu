#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_raycast.inl"
template struct seamless::kernels::TsdfRaycast<seamless::CudaExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::TsdfRaycast<seamless::CudaExec, seamless::kernels::DenseAccess>;
template struct seamless::kernels::TsdfRaycast<seamless::CudaExec, seamless::kernels::WindowedHashAccess>;
