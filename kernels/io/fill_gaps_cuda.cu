#include "core/exec_cuda.cuh"
#include "kernels/io/fill_gaps.inl"
template struct seamless::kernels::FillGaps<seamless::CudaExec>;
