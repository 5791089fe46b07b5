#include "core/exec_cuda.cuh"
#include "staged_probe.inl"
template struct seamless::probe::StagedProbe<seamless::CudaExec>;
