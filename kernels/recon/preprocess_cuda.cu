#include "core/exec_cuda.cuh"
#include "kernels/recon/preprocess.inl"
SEAMLESS_INSTANTIATE_PREPROCESS(seamless::CudaExec)
