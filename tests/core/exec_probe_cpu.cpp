#include "core/exec_cpu.hpp"
#include "exec_probe.inl"
SEAMLESS_INSTANTIATE_PROBE(seamless::CpuExec)
