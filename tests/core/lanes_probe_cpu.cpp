#include "core/exec_cpu.hpp"
#include "lanes_probe.inl"
template struct seamless::probe::LanesProbe<seamless::CpuExec>;
