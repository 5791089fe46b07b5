#include "core/exec_cpu.hpp"
#include "kernels/recon/preprocess.inl"
SEAMLESS_INSTANTIATE_PREPROCESS(seamless::CpuExec)
