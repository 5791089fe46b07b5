#include "core/exec_cuda.cuh"
#include "lanes_probe.inl"
SEAMLESS_INSTANTIATE_LANES_PROBE(seamless::CudaExec)
