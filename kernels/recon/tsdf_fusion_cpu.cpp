#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_fusion.inl"
template struct seamless::kernels::TsdfFusion<seamless::CpuExec>;
