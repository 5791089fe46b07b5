#include "core/exec_cuda.cuh"
#include "kernels/recon/preprocess.inl"
template struct seamless::kernels::Preprocess<seamless::CudaExec>;
