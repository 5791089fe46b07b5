#include "core/exec_cuda.cuh"
#include "staged_probe.inl"
SEAMLESS_INSTANTIATE_STAGED_PROBE(seamless::CudaExec)
