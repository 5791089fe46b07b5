#include "core/exec_cpu.hpp"
#include "kernels/recon/preprocess.inl"
template struct seamless::kernels::Preprocess<seamless::CpuExec>;
