// Atomics usable from kernels on both backends.
#pragma once
#include <atomic>
#include <cstdint>

#include "core/hd.hpp"

namespace seamless {

template <class T> SEAMLESS_HD inline T atomic_add(T* p, T v) {
#ifdef __CUDA_ARCH__
  return atomicAdd(p, v);
#else
  return std::atomic_ref<T>(*p).fetch_add(v, std::memory_order_relaxed);
#endif
}

// Returns the old value; stores desired only if *p == expected.
template <class T> SEAMLESS_HD inline T atomic_cas(T* p, T expected, T desired) {
#ifdef __CUDA_ARCH__
  return atomicCAS(p, expected, desired);
#else
  std::atomic_ref<T>(*p).compare_exchange_strong(expected, desired, std::memory_order_acq_rel);
  return expected;
#endif
}

template <class T> SEAMLESS_HD inline T atomic_exch(T* p, T v) {
#ifdef __CUDA_ARCH__
  return atomicExch(p, v);
#else
  return std::atomic_ref<T>(*p).exchange(v, std::memory_order_acq_rel);
#endif
}

template <class T> SEAMLESS_HD inline T atomic_max(T* p, T v) {
#ifdef __CUDA_ARCH__
  return atomicMax(p, v);
#else
  std::atomic_ref<T> a(*p);
  T old = a.load(std::memory_order_relaxed);
  while (old < v && !a.compare_exchange_weak(old, v, std::memory_order_relaxed)) {
  }
  return old;
#endif
}

template <class T> SEAMLESS_HD inline T atomic_min(T* p, T v) {
#ifdef __CUDA_ARCH__
  return atomicMin(p, v);
#else
  std::atomic_ref<T> a(*p);
  T old = a.load(std::memory_order_relaxed);
  while (v < old && !a.compare_exchange_weak(old, v, std::memory_order_relaxed)) {
  }
  return old;
#endif
}

template <class T> SEAMLESS_HD inline T atomic_load(const T* p) {
#ifdef __CUDA_ARCH__
  return *static_cast<const volatile T*>(p);
#else
  return std::atomic_ref<T>(*const_cast<T*>(p)).load(std::memory_order_acquire);
#endif
}

}  // namespace seamless
