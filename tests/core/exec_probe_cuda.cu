#include "core/exec_cuda.cuh"
#include "exec_probe.inl"
SEAMLESS_INSTANTIATE_PROBE(seamless::CudaExec)
