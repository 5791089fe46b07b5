// SEAMLESS_HD marks a function usable on the host and in CUDA kernels: every computation is written
// once and compiled for both backends (core/exec.hpp). Under g++ it expands to nothing.
#pragma once
#if defined(__CUDACC__)
#define SEAMLESS_HD __host__ __device__
#define SEAMLESS_DEVICE_CODE 1
#else
#define SEAMLESS_HD
#define SEAMLESS_DEVICE_CODE 0
#endif
