#include "core/exec_cpu.hpp"
#include "kernels/io/undistort.inl"
template struct seamless::kernels::Undistort<seamless::CpuExec>;
