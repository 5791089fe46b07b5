// Which CUDA architectures of a build run on which GPU: the run-time check of a device's compute
// capability against the build (core/device.cpp) and what to rebuild with.
#pragma once
#include <string>

namespace seamless {

// How a build for the CUDA architectures `archs` (CMake's CUDA_ARCHITECTURES, separated by spaces
// or semicolons: "75-real 86 90-virtual") runs on a GPU of compute capability major.minor.
// Machine code (SASS) for sm_XY runs on X.Z with Z >= Y; PTX for compute_XY is compiled by the
// driver, at start-up, for any card of compute capability XY or newer; "N" is both, "N-real" SASS
// only, "N-virtual" PTX only, "Na" SASS for exactly N ("Nf" as N-real). `unknown` for lists naming no number
// ("native", "all").
enum class CudaArchMatch { machine_code, ptx_only, none, unknown };
CudaArchMatch cuda_arch_match(const std::string& archs, int major, int minor);
// What a user of such a GPU should know, or "" when the build has its machine code (or cannot
// tell): for `none` that the kernels cannot run and the -DSEAMLESS_CUDA_ARCH to rebuild with, for
// `ptx_only` that they are compiled at start-up and how to build its machine code instead.
std::string cuda_arch_advice(const std::string& archs, int major, int minor, const std::string& gpu_name);

}  // namespace seamless
