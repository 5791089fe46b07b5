#include "core/exec_cpu.hpp"
#include "lanes_probe.inl"
SEAMLESS_INSTANTIATE_LANES_PROBE(seamless::CpuExec)
