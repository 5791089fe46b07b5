#include "core/exec_cpu.hpp"
#include "kernels/io/undistort.inl"
SEAMLESS_INSTANTIATE_UNDISTORT(seamless::CpuExec)
