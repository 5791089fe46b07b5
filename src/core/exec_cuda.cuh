// The CUDA executor. Include only from *_cuda.cu instantiation files.
#pragma once
#include <cub/cub.cuh>

#include <cstdint>

#include "core/cuda_check.hpp"
#include "core/exec.hpp"

namespace seamless {

namespace cuda_detail {
// One growing scratch allocation shared by the collectives (they run one at a time on stream 0).
void* scratch(std::size_t bytes);
int multiprocessors();

template <class F>
__global__ void for_each_kernel(std::int64_t n, F fn) {
  std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) fn(i);
}

struct Plus {
  template <class T>
  __device__ T operator()(const T& a, const T& b) const { return a + b; }
};

template <int kThreads, class T, class F>
__global__ void transform_reduce_kernel(std::int64_t n, F fn, T* partial) {
  using BlockReduce = cub::BlockReduce<T, kThreads>;
  __shared__ typename BlockReduce::TempStorage tmp;
  T local{};
  for (std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * kThreads + threadIdx.x; i < n;
       i += static_cast<std::int64_t>(gridDim.x) * kThreads)
    local = local + fn(i);
  T block = BlockReduce(tmp).Reduce(local, Plus{});
  if (threadIdx.x == 0) partial[blockIdx.x] = block;
}

template <int kThreads, class T>
__global__ void sum_partials_kernel(const T* partial, int m, T* out) {
  using BlockReduce = cub::BlockReduce<T, kThreads>;
  __shared__ typename BlockReduce::TempStorage tmp;
  T local{};
  for (int i = threadIdx.x; i < m; i += kThreads) local = local + partial[i];
  T total = BlockReduce(tmp).Reduce(local, Plus{});
  if (threadIdx.x == 0) *out = total;
}
}  // namespace cuda_detail

template <class F>
void CudaExec::for_each(std::int64_t n, F fn) const {
  if (n <= 0) return;
  constexpr int kThreads = 256;
  auto blocks = static_cast<unsigned>((n + kThreads - 1) / kThreads);
  cuda_detail::for_each_kernel<<<blocks, kThreads>>>(n, fn);
  SEAMLESS_CUDA_CHECK_LAUNCH("for_each");
}

template <class T>
T CudaExec::exclusive_scan(const T* in, T* out, std::int64_t n) const {
  if (n <= 0) return T{};
  T last_in{};
  SEAMLESS_CUDA_CHECK(cudaMemcpy(&last_in, in + n - 1, sizeof(T), cudaMemcpyDeviceToHost));
  std::size_t bytes = 0;
  SEAMLESS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(nullptr, bytes, in, out, n));
  SEAMLESS_CUDA_CHECK(cub::DeviceScan::ExclusiveSum(cuda_detail::scratch(bytes), bytes, in, out, n));
  T last_out{};
  SEAMLESS_CUDA_CHECK(cudaMemcpy(&last_out, out + n - 1, sizeof(T), cudaMemcpyDeviceToHost));
  return last_out + last_in;
}

template <class K, class V>
void CudaExec::sort_by_key(K* keys, V* values, std::int64_t n, int key_bits) const {
  if (n <= 1) return;
  // Scratch layout: [alternate keys | alternate values | CUB temp].
  auto align = [](std::size_t b) { return (b + 255) / 256 * 256; };
  std::size_t kb = align(sizeof(K) * n), vb = align(sizeof(V) * n);
  std::size_t tmp = 0;
  cub::DoubleBuffer<K> dk(keys, nullptr);
  cub::DoubleBuffer<V> dv(values, nullptr);
  SEAMLESS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, tmp, dk, dv, n, 0, key_bits));
  char* s = static_cast<char*>(cuda_detail::scratch(kb + vb + tmp));
  dk = cub::DoubleBuffer<K>(keys, reinterpret_cast<K*>(s));
  dv = cub::DoubleBuffer<V>(values, reinterpret_cast<V*>(s + kb));
  SEAMLESS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(s + kb + vb, tmp, dk, dv, n, 0, key_bits));
  if (dk.Current() != keys) {
    SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(keys, dk.Current(), sizeof(K) * n, cudaMemcpyDeviceToDevice));
    SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(values, dv.Current(), sizeof(V) * n, cudaMemcpyDeviceToDevice));
  }
}

template <class T, class F>
T CudaExec::transform_reduce(std::int64_t n, T init, F fn) const {
  if (n <= 0) return init;
  constexpr int kThreads = 256;
  std::int64_t wanted = (n + kThreads - 1) / kThreads;
  int blocks = static_cast<int>(std::min<std::int64_t>(wanted, 4 * cuda_detail::multiprocessors()));
  T* partial = static_cast<T*>(cuda_detail::scratch(sizeof(T) * (blocks + 1)));
  cuda_detail::transform_reduce_kernel<kThreads, T><<<blocks, kThreads>>>(n, fn, partial);
  SEAMLESS_CUDA_CHECK_LAUNCH("transform_reduce");
  cuda_detail::sum_partials_kernel<kThreads, T><<<1, kThreads>>>(partial, blocks, partial + blocks);
  SEAMLESS_CUDA_CHECK_LAUNCH("transform_reduce partials");
  T total{};
  SEAMLESS_CUDA_CHECK(cudaMemcpy(&total, partial + blocks, sizeof(T), cudaMemcpyDeviceToHost));
  return init + total;
}

}  // namespace seamless
