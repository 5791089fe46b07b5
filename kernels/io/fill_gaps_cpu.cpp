#include "core/exec_cpu.hpp"
#include "kernels/io/fill_gaps.inl"
SEAMLESS_INSTANTIATE_FILL_GAPS(seamless::CpuExec)
