#include "core/exec_cuda.cuh"
#include "kernels/io/undistort.inl"
template struct seamless::kernels::Undistort<seamless::CudaExec>;
