#include "core/exec_cpu.hpp"
#include "kernels/io/fill_gaps.inl"
template struct seamless::kernels::FillGaps<seamless::CpuExec>;
