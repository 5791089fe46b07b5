#include "core/exec_cuda.cuh"
#include "kernels/io/kinect_depth.inl"
template struct seamless::kernels::KinectDepth<seamless::CudaExec>;
