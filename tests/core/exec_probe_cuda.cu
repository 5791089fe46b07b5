#include "core/exec_cuda.cuh"
#include "exec_probe.inl"
template struct seamless::probe::ExecProbe<seamless::CudaExec>;
