#include "core/exec_cpu.hpp"
#include "kernels/recon/tsdf_extract.inl"
SEAMLESS_INSTANTIATE_TSDF_EXTRACT(seamless::CpuExec)
