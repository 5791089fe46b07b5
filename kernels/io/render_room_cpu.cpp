#include "core/exec_cpu.hpp"
#include "kernels/io/render_room.inl"
SEAMLESS_INSTANTIATE_RENDER_ROOM(seamless::CpuExec)
