#include "core/exec_cuda.cuh"
#include "kernels/io/render_room.inl"
SEAMLESS_INSTANTIATE_RENDER_ROOM(seamless::CudaExec)
