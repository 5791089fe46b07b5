#include "core/exec_cuda.cuh"
#include "kernels/io/render_room.inl"
template struct seamless::kernels::RenderRoom<seamless::CudaExec>;
