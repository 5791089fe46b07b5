#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_extract.inl"
template struct seamless::kernels::TsdfExtract<seamless::CudaExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::TsdfExtract<seamless::CudaExec, seamless::kernels::DenseAccess>;
