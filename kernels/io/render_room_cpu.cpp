#include "core/exec_cpu.hpp"
#include "kernels/io/render_room.inl"
template struct seamless::kernels::RenderRoom<seamless::CpuExec>;
