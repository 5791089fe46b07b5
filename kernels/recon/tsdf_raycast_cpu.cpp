#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_raycast.inl"
template struct seamless::kernels::TsdfRaycast<seamless::CpuExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::TsdfRaycast<seamless::CpuExec, seamless::kernels::DenseAccess>;
template struct seamless::kernels::TsdfRaycast<seamless::CpuExec, seamless::kernels::WindowedHashAccess>;
