// Executors: the one place where the two backends differ (see DESIGN, "One kernel, two backends").
//
// A kernel family is a template over the executor type and uses only:
//   ex.for_each(n, fn)                   fn(i) for i in [0, n), in parallel
//   ex.exclusive_scan(in, out, n)        out[i] = sum of in[0..i); returns the total (to the host)
//   ex.sort_by_key(keys, values, n, b)   stable sort of (key, value) pairs by the low b bits of key
//   ex.transform_reduce(n, init, fn)     init + sum of fn(i); T needs operator+ (returned to host)
//   ex.synchronize()
// plus the SEAMLESS_HD atomics in core/atomics.hpp. Pointers passed in live on ex.device.
//
// CpuExec's members are defined in core/exec_cpu.hpp (OpenMP), CudaExec's in core/exec_cuda.cuh
// (CUDA + CUB). Host code includes only this header and calls kernel templates through
// with_exec(); the kernel's .inl is compiled once per backend by two tiny instantiation files.
#pragma once
#include <cstdint>

#include "core/device.hpp"
#include "core/error.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

struct CpuExec {
  static constexpr Device device = Device::CPU;
  template <class F> void for_each(std::int64_t n, F fn) const;
  template <class T> T exclusive_scan(const T* in, T* out, std::int64_t n) const;
  template <class K, class V> void sort_by_key(K* keys, V* values, std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class T, class F> T transform_reduce(std::int64_t n, T init, F fn) const;
  void synchronize() const {}
};

struct CudaExec {
  static constexpr Device device = Device::CUDA;
  template <class F> void for_each(std::int64_t n, F fn) const;
  template <class T> T exclusive_scan(const T* in, T* out, std::int64_t n) const;
  template <class K, class V> void sort_by_key(K* keys, V* values, std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class T, class F> T transform_reduce(std::int64_t n, T init, F fn) const;
  void synchronize() const;
};

// Calls fn(executor) with the executor for device d.
template <class F>
decltype(auto) with_exec(Device d, F&& fn) {
#if SEAMLESS_HAS_CUDA
  if (d == Device::CUDA) return fn(CudaExec{});
#else
  if (d == Device::CUDA) throw Error("the CUDA backend is not built into this binary");
#endif
  return fn(CpuExec{});
}

}  // namespace seamless
