#include "core/exec_cuda.cuh"
#include "lanes_probe.inl"
template struct seamless::probe::LanesProbe<seamless::CudaExec>;
