#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_extract.inl"
template struct seamless::kernels::TsdfExtract<seamless::CpuExec, seamless::kernels::HashAccess>;
template struct seamless::kernels::TsdfExtract<seamless::CpuExec, seamless::kernels::DenseAccess>;
