#include "core/exec_cpu.hpp"
#include "staged_probe.inl"
template struct seamless::probe::StagedProbe<seamless::CpuExec>;
