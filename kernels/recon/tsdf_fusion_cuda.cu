#include "core/exec_cuda.cuh"
#include "kernels/recon/tsdf_fusion.inl"
template struct seamless::kernels::TsdfFusion<seamless::CudaExec>;
