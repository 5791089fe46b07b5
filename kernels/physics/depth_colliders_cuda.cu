#include "core/exec_cuda.cuh"
#include "kernels/physics/depth_colliders.inl"
template struct seamless::kernels::DepthColliders<seamless::CudaExec>;
