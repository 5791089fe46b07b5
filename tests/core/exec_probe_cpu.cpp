#include "core/exec_cpu.hpp"
#include "exec_probe.inl"
template struct seamless::probe::ExecProbe<seamless::CpuExec>;
