#include "core/exec_cpu.hpp"
#include "kernels/io/kinect_depth.inl"
template struct seamless::kernels::KinectDepth<seamless::CpuExec>;
