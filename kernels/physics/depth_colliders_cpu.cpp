#include "core/exec_cpu.hpp"
#include "kernels/physics/depth_colliders.inl"
template struct seamless::kernels::DepthColliders<seamless::CpuExec>;
