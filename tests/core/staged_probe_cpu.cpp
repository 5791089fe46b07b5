#include "core/exec_cpu.hpp"
#include "staged_probe.inl"
SEAMLESS_INSTANTIATE_STAGED_PROBE(seamless::CpuExec)
