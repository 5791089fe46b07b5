#include "core/exec_cuda.cuh"
#include "kernels/io/fill_gaps.inl"
SEAMLESS_INSTANTIATE_FILL_GAPS(seamless::CudaExec)
