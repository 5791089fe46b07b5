#include "core/exec_cuda.cuh"
#include "kernels/physics/contacts.inl"
template struct seamless::kernels::Contacts<seamless::CudaExec>;
