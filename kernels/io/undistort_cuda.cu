#include "core/exec_cuda.cuh"
#include "kernels/io/undistort.inl"
SEAMLESS_INSTANTIATE_UNDISTORT(seamless::CudaExec)
