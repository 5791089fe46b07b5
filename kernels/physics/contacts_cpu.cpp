#include "core/exec_cpu.hpp"
#include "kernels/physics/contacts.inl"
template struct seamless::kernels::Contacts<seamless::CpuExec>;
