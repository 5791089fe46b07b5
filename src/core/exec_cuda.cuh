// The CUDA executor. Include only from *_cuda.cu instantiation files.
#pragma once
#include <cooperative_groups.h>
// The three CUB algorithms used below, not all of <cub/cub.cuh>: a quarter fewer lines for every
// *_cuda.cu file to compile (docs/PERFORMANCE.md, "Build time").
#include <cub/block/block_reduce.cuh>
#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_scan.cuh>
#include <cub/util_type.cuh>
#include <cuda/std/tuple>

#include <algorithm>
#include <cstdint>
#include <string>
#include <type_traits>

#include "core/cuda_check.hpp"
#include "core/exec.hpp"

namespace seamless {

// Every primitive of core/exec.hpp's list, with the forms the kernels call.
static_assert(Executor<CudaExec>);

namespace cuda_detail {
// One growing scratch allocation shared by the collectives (they run one at a time on stream 0).
void* scratch(std::size_t bytes);
// A device slot for a host-returned reduction's total, apart from scratch (which holds the partials).
void* result_slot(std::size_t bytes);
int multiprocessors();
// Dynamic shared memory one block may use once the kernel opts in (cudaDevAttrMaxSharedMemoryPerBlockOptin).
int max_shared_per_block();

template <class F> __global__ void for_each_kernel(std::int64_t n, F fn) {
  std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) fn(i);
}

struct Plus {
  template <class T> __device__ T operator()(const T& a, const T& b) const { return a + b; }
};

// Zeroed once; the last block of every reduction puts it back to zero (see below).
unsigned* reduce_counter();

// One launch for the whole sum (the "last block" pattern of the CUDA samples' threadFenceReduction):
// every block writes its partial, and the block that finishes last, as counted by an atomic on a
// counter that starts at zero, adds the partials and writes *out. No second launch, and *out
// stays on the device for the next kernel in the stream.
// The sum runs in the type fn returns, Local, and is widened once into T at the end (T{} + total):
// a narrower Local (float terms of a double sum) halves the registers, so twice the threads are in
// flight. Its rounding stays small because the sum is a tree: a thread adds its few elements
// (n / threads in flight), then the block and the partials are summed pairwise (CUB), so the
// relative error grows with log2(n), not with n as in one long float sum.
template <int kThreads, class T, class F, class G>
__global__ void transform_reduce_kernel(std::int64_t n, F fn, decltype(fn(std::int64_t{}))* partial, unsigned* counter,
                                        T* out, G then) {
  using Local = decltype(fn(std::int64_t{}));
  using BlockReduce = cub::BlockReduce<Local, kThreads>;
  __shared__ typename BlockReduce::TempStorage tmp;
  __shared__ bool last;
  Local local{};
  for (std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * kThreads + threadIdx.x; i < n;
       i += static_cast<std::int64_t>(gridDim.x) * kThreads)
    local = local + fn(i);
  Local block = BlockReduce(tmp).Reduce(local, Plus{});
  if (threadIdx.x == 0) {
    partial[blockIdx.x] = block;
    __threadfence();  // the partial is visible device-wide before the counter says so
    last = atomicAdd(counter, 1u) == gridDim.x - 1;
  }
  __syncthreads();
  if (!last) return;
  __threadfence();
  Local sum{};
  for (unsigned i = threadIdx.x; i < gridDim.x; i += kThreads) sum = sum + partial[i];
  __syncthreads();  // tmp is reused
  Local total = BlockReduce(tmp).Reduce(sum, Plus{});
  if (threadIdx.x == 0) {
    *out = T{} + total;
    *counter = 0;
    then();
  }
}

// The float components of a transform_reduce_rounds term, padded to whole warps: kQ per lane.
template <class Local> struct RoundWords {
  static_assert(sizeof(Local) % sizeof(float) == 0 && alignof(Local) == alignof(float),
                "transform_reduce_rounds: fn must return a struct of floats (summed component by component)");
  static constexpr int kWords = sizeof(Local) / sizeof(float);
  static constexpr int kQ = (kWords + 31) / 32;
};

// One butterfly step of warp_reduce_scatter over the first M entries of v: the lanes whose bit o
// is set keep the upper half, the others the lower, and each adds its partner's half of the kept
// part. M is a template argument so that every index is a constant (v stays in registers).
template <int M, int N> __device__ __forceinline__ void butterfly_step(float (&v)[N], unsigned lane, int o) {
  const bool upper = lane & static_cast<unsigned>(o);
#pragma unroll
  for (int j = 0; j < M / 2; ++j) {
    const float keep = upper ? v[j + M / 2] : v[j], give = upper ? v[j] : v[j + M / 2];
    v[j] = keep + __shfl_xor_sync(0xFFFFFFFFu, give, o);
  }
}

// A warp's reduce-scatter of 32 x kQ floats: five butterfly steps (16 + 8 + 4 + 2 + 1 shuffles
// x kQ, not 5 x 32 x kQ for a shuffle tree per component). Lane l ends with the warp's sums of
// components [l kQ, l kQ + kQ) in v[0, kQ): each step's upper half goes with that step's lane bit.
template <int kQ> __device__ __forceinline__ void warp_reduce_scatter(float (&v)[32 * kQ], unsigned lane) {
  butterfly_step<32 * kQ>(v, lane, 16);
  butterfly_step<16 * kQ>(v, lane, 8);
  butterfly_step<8 * kQ>(v, lane, 4);
  butterfly_step<4 * kQ>(v, lane, 2);
  butterfly_step<2 * kQ>(v, lane, 1);
}

// transform_reduce_rounds in one cooperative launch (every block resident at once, so that the
// grid can wait for itself). Each round, a block sums its terms component by component (a warp
// reduce-scatter, then the warps' sums in shared memory) into partial[c x blocks + block]
// (component-major), and the grid waits; block 0 then sums each component over the blocks, a
// warp per component with coalesced loads, and its thread 0 writes *out and runs then(round, sum)
// while the others wait again; every block then reads the same stop flag, so the grid leaves
// the loop together. A round costs two grid barriers instead of a launch and the "last block"
// counter of transform_reduce_kernel, and the sums of a 30-float term take a few hundred cycles
// where a block reduction of the struct took thousands (docs/PERFORMANCE.md). At least
// 2 blocks per multiprocessor: the RGB-D term's pixel function and the double-precision solve
// would otherwise take 175 registers, one block of 8 warps per SM, too few to hide the pixels'
// gathers (faster with the bound despite a few spilled bytes, docs/PERFORMANCE.md; ICP fits in 126
// registers either way).
template <int kThreads, class T, class F, class G>
__global__ void __launch_bounds__(kThreads, 2)
    transform_reduce_rounds_kernel(std::int64_t n, int rounds, F fn, float* partial, int* stop, T* out, G then) {
  using Local = decltype(fn(std::int64_t{}));
  using W = RoundWords<Local>;
  constexpr int kWarps = kThreads / 32;
  __shared__ float warp_sums[kWarps][32 * W::kQ];
  __shared__ float total_words[W::kWords];
  const unsigned lane = threadIdx.x & 31u, warp = threadIdx.x >> 5;
  const cooperative_groups::grid_group grid = cooperative_groups::this_grid();
  for (int r = 0; r < rounds; ++r) {
    Local local{};
    for (std::int64_t i = static_cast<std::int64_t>(blockIdx.x) * kThreads + threadIdx.x; i < n;
         i += static_cast<std::int64_t>(gridDim.x) * kThreads)
      local = local + fn(i);
    float v[32 * W::kQ];
#pragma unroll
    for (int k = 0; k < 32 * W::kQ; ++k) v[k] = k < W::kWords ? reinterpret_cast<const float*>(&local)[k] : 0.f;
    warp_reduce_scatter<W::kQ>(v, lane);
#pragma unroll
    for (int q = 0; q < W::kQ; ++q) warp_sums[warp][lane * W::kQ + q] = v[q];
    __syncthreads();
    for (int c = threadIdx.x; c < W::kWords; c += kThreads) {
      float sum = 0.f;
#pragma unroll
      for (int w = 0; w < kWarps; ++w) sum += warp_sums[w][c];
      partial[static_cast<std::int64_t>(c) * gridDim.x + blockIdx.x] = sum;
    }
    grid.sync();  // every partial written (the barrier orders memory grid-wide)
    if (blockIdx.x == 0) {
      // Warp w sums components w, w + kWarps, ...; its lanes stride over the blocks, kBatch
      // loads per component in flight at once (one trip of the outer loop up to 32 x kBatch
      // blocks), then a shuffle tree per component.
      constexpr int kPerWarp = (W::kWords + kWarps - 1) / kWarps, kBatch = 16;
      float acc[kPerWarp] = {};
      for (unsigned b0 = lane; b0 < gridDim.x; b0 += 32 * kBatch) {
#pragma unroll
        for (int m = 0; m < kPerWarp; ++m) {
          const int c = static_cast<int>(warp) + kWarps * m;
          const float* p = partial + static_cast<std::int64_t>(c) * gridDim.x;
#pragma unroll
          for (int k = 0; k < kBatch; ++k) {
            const unsigned b = b0 + 32u * k;
            acc[m] += c < W::kWords && b < gridDim.x ? p[b] : 0.f;
          }
        }
      }
#pragma unroll
      for (int m = 0; m < kPerWarp; ++m) {
        const int c = static_cast<int>(warp) + kWarps * m;
#pragma unroll
        for (int o = 16; o >= 1; o >>= 1) acc[m] += __shfl_xor_sync(0xFFFFFFFFu, acc[m], o);
        if (lane == 0 && c < W::kWords) total_words[c] = acc[m];
      }
      __syncthreads();
      if (threadIdx.x == 0) {
        const T sum = T{} + *reinterpret_cast<const Local*>(total_words);
        *out = sum;
        *stop = then(r, sum) ? 1 : 0;
      }
    }
    grid.sync();  // then's writes seen by every block's next round; partials and warp_sums free again
    if (*static_cast<volatile int*>(stop)) break;
  }
}
}  // namespace cuda_detail

template <class F> void CudaExec::for_each(std::int64_t n, F fn) const {
  if (n <= 0) return;
  constexpr int kThreads = 256;
  auto blocks = static_cast<unsigned>((n + kThreads - 1) / kThreads);
  cuda_detail::for_each_kernel<<<blocks, kThreads, 0, static_cast<cudaStream_t>(stream)>>>(n, fn);
  SEAMLESS_CUDA_CHECK_LAUNCH("for_each");
}

namespace cuda_detail {
// Groups of 2^log2_lanes consecutive threads, one per element; blocks of 256 threads hold whole
// groups, and groups never straddle a warp, so a group's shuffles stay within its warp.
template <class F> __device__ __forceinline__ void grouped_element(std::int64_t n, int log2_lanes, F& fn) {
  const std::int64_t t = static_cast<std::int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  const std::int64_t i = t >> log2_lanes;
  if (i >= n) return;  // the whole group leaves: its lanes share i
  Lanes g;
  g.size = 1 << log2_lanes;
  g.lane = static_cast<int>(t) & (g.size - 1);
  g.first = static_cast<int>(threadIdx.x & 31u) & ~(g.size - 1);
  g.mask = g.size == 32 ? 0xFFFFFFFFu : ((1u << g.size) - 1u) << g.first;
  fn(i, g);
}

template <class F> __global__ void for_each_grouped_kernel(std::int64_t n, int log2_lanes, F fn) {
  grouped_element(n, log2_lanes, fn);
}

// The same with kMinBlocks blocks of kThreads resident per multiprocessor (registers capped to fit).
template <int kThreads, int kMinBlocks, class F>
__global__ void __launch_bounds__(kThreads, kMinBlocks)
    for_each_grouped_bounded_kernel(std::int64_t n, int log2_lanes, F fn) {
  grouped_element(n, log2_lanes, fn);
}

// Up to kMax phases of for_each_phases in one block: __syncthreads() between phases makes each
// phase's global writes visible to the whole block (CUDA programming guide, synchronization
// functions), which is all a sweep needs when one block holds it. One block of 1024 threads,
// instead of one launch per phase: a small cloth's colour has fewer edges than a launch costs.
struct PhaseChunk {
  static constexpr int kMax = 32;
  int count = 0;
  std::int64_t begin[kMax], end[kMax];
};

template <class F> __global__ void __launch_bounds__(1024) for_each_phases_kernel(PhaseChunk c, int first_phase, F fn) {
  for (int p = 0; p < c.count; ++p) {
    for (std::int64_t i = c.begin[p] + threadIdx.x; i < c.end[p]; i += blockDim.x) fn(first_phase + p, i);
    __syncthreads();
  }
}

// fn(p, begin + i): one phase as a plain for_each (phases too large for one block).
template <class F> struct PhaseAt {
  F fn;
  int p;
  std::int64_t begin;
  __device__ void operator()(std::int64_t i) const { fn(p, begin + i); }
};

// for_each_phases_staged: one array's place for the sweep, bytes [offset, offset + count x
// sizeof(T)) of the block's dynamic shared memory if `shared`, else ptr.
template <class T> struct StagedSlot {
  T* ptr;
  std::int64_t count;
  unsigned offset;
  int shared;
};

template <class T> __device__ T* staged_where(const StagedSlot<T>& s, unsigned char* smem) {
  return s.shared ? reinterpret_cast<T*>(smem + s.offset) : s.ptr;
}

template <class T> __device__ void stage_in(const StagedSlot<T>& s, unsigned char* smem) {
  if (!s.shared) return;
  using U = std::remove_const_t<T>;
  U* d = reinterpret_cast<U*>(smem + s.offset);
  for (std::int64_t i = threadIdx.x; i < s.count; i += blockDim.x) d[i] = s.ptr[i];
}

template <class T> __device__ void stage_out(const StagedSlot<T>& s, unsigned char* smem) {
  if constexpr (!std::is_const_v<T>) {
    if (!s.shared) return;
    const T* d = reinterpret_cast<const T*>(smem + s.offset);
    for (std::int64_t i = threadIdx.x; i < s.count; i += blockDim.x) s.ptr[i] = d[i];
  }
}

// for_each_phases_kernel with the staged arrays copied into shared memory before the first phase
// and the writable ones copied back after the last (whose __syncthreads() orders the copy after
// every phase's writes); fn sees each array where it lives.
template <class F, class... T>
__global__ void __launch_bounds__(1024)
    for_each_phases_staged_kernel(PhaseChunk c, int first_phase, F fn, StagedSlot<T>... s) {
  extern __shared__ __align__(16) unsigned char staged_smem[];
  (stage_in(s, staged_smem), ...);
  __syncthreads();
  for (int p = 0; p < c.count; ++p) {
    for (std::int64_t i = c.begin[p] + threadIdx.x; i < c.end[p]; i += blockDim.x)
      fn(first_phase + p, i, staged_where(s, staged_smem)...);
    __syncthreads();
  }
  (stage_out(s, staged_smem), ...);
}

// fn(p, begin + i, a...) with the arrays in global memory: one phase as a plain for_each.
template <class F, class... T> struct StagedPhaseAt {
  F fn;
  int p;
  std::int64_t begin;
  cuda::std::tuple<T*...> a;
  __device__ void operator()(std::int64_t i) const {
    cuda::std::apply([&](T*... x) { fn(p, begin + i, x...); }, a);
  }
};
}  // namespace cuda_detail

template <class F> void CudaExec::for_each_grouped(std::int64_t n, int max_lanes, F fn) const {
  for_each_grouped(n, max_lanes, fn, MinBlocks<0>{});
}

template <int B, class F> void CudaExec::for_each_grouped(std::int64_t n, int max_lanes, F fn, MinBlocks<B>) const {
  if (n <= 0) return;
  int log2_lanes = 0;
  while ((1 << log2_lanes) < lanes(n, max_lanes)) ++log2_lanes;
  constexpr int kThreads = 256;
  auto blocks = static_cast<unsigned>(((n << log2_lanes) + kThreads - 1) / kThreads);
  const auto st = static_cast<cudaStream_t>(stream);
  if constexpr (B <= 0) cuda_detail::for_each_grouped_kernel<<<blocks, kThreads, 0, st>>>(n, log2_lanes, fn);
  else cuda_detail::for_each_grouped_bounded_kernel<kThreads, B><<<blocks, kThreads, 0, st>>>(n, log2_lanes, fn);
  SEAMLESS_CUDA_CHECK_LAUNCH("for_each_grouped");
}

template <class F>
void CudaExec::for_each_phases(int phases, const std::int64_t* begin, const std::int64_t* end, F fn) const {
  // One block runs a phase of up to 2 x 1024 elements in about the time of one launch (two
  // dependent rounds of loads); larger phases get the whole device, a launch each.
  constexpr int kThreads = 1024;
  constexpr std::int64_t kOneBlock = 2 * kThreads;
  std::int64_t largest = 0;
  for (int p = 0; p < phases; ++p) largest = std::max(largest, end[p] - begin[p]);
  if (largest > kOneBlock) {
    for (int p = 0; p < phases; ++p) for_each(end[p] - begin[p], cuda_detail::PhaseAt<F>{fn, p, begin[p]});
    return;
  }
  for (int first = 0; first < phases; first += cuda_detail::PhaseChunk::kMax) {
    cuda_detail::PhaseChunk c;
    c.count = std::min(phases - first, cuda_detail::PhaseChunk::kMax);
    for (int p = 0; p < c.count; ++p) c.begin[p] = begin[first + p], c.end[p] = end[first + p];
    cuda_detail::for_each_phases_kernel<<<1, kThreads, 0, static_cast<cudaStream_t>(stream)>>>(c, first, fn);
    SEAMLESS_CUDA_CHECK_LAUNCH("for_each_phases");
  }
}

template <class F, class... T>
void CudaExec::for_each_phases_staged(int phases, const std::int64_t* begin, const std::int64_t* end, F fn,
                                      Staged<T>... arrays) const {
  // The same split as for_each_phases: phases of up to kOneBlock elements run in one block.
  constexpr int kThreads = 1024;
  constexpr std::int64_t kOneBlock = 2 * kThreads;
  std::int64_t largest = 0;
  for (int p = 0; p < phases; ++p) largest = std::max(largest, end[p] - begin[p]);
  if (largest > kOneBlock) {
    for (int p = 0; p < phases; ++p)
      for_each(end[p] - begin[p], cuda_detail::StagedPhaseAt<F, T...>{fn, p, begin[p], {arrays.ptr...}});
    return;
  }
  // Shared memory for the arrays that fit, in argument order (16-byte aligned places; a braced
  // list is evaluated left to right).
  static const std::size_t budget = static_cast<std::size_t>(cuda_detail::max_shared_per_block());
  std::size_t used = 0;
  auto place = [&](auto a) {
    using E = std::remove_pointer_t<decltype(a.ptr)>;
    static_assert(std::is_trivially_copyable_v<E>, "Staged<T>: T must be trivially copyable");
    cuda_detail::StagedSlot<E> s{a.ptr, a.count, 0u, 0};
    const std::size_t bytes = (static_cast<std::size_t>(a.count) * sizeof(E) + 15) / 16 * 16;
    if (a.count > 0 && used + bytes <= budget) s.offset = static_cast<unsigned>(used), s.shared = 1, used += bytes;
    return s;
  };
  const cuda::std::tuple<cuda_detail::StagedSlot<T>...> slots{place(arrays)...};
  auto kernel = cuda_detail::for_each_phases_staged_kernel<F, T...>;
  if (used > 48 * 1024) {
    // Over the default 48 KB a kernel must opt in, once (before any graph capture: the first
    // step of a scene runs directly).
    static const bool opted_in = [&] {
      SEAMLESS_CUDA_CHECK(
          cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, static_cast<int>(budget)));
      return true;
    }();
    (void)opted_in;
  }
  for (int first = 0; first < phases; first += cuda_detail::PhaseChunk::kMax) {
    cuda_detail::PhaseChunk c;
    c.count = std::min(phases - first, cuda_detail::PhaseChunk::kMax);
    for (int p = 0; p < c.count; ++p) c.begin[p] = begin[first + p], c.end[p] = end[first + p];
    cuda::std::apply(
        [&](auto... s) { kernel<<<1, kThreads, used, static_cast<cudaStream_t>(stream)>>>(c, first, fn, s...); },
        slots);
    SEAMLESS_CUDA_CHECK_LAUNCH("for_each_phases_staged");
  }
}

template <class T> T CudaExec::exclusive_scan(const T* in, T* out, std::int64_t n) const {
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

namespace cuda_detail {
struct SortLayout {
  std::size_t keys, values, cub;  // bytes: alternate keys, alternate values, CUB temp (256-aligned)
  std::size_t total() const { return keys + values + cub; }
};
template <class K, class V> SortLayout sort_layout(std::int64_t n, int key_bits, cudaStream_t stream = nullptr) {
  auto align = [](std::size_t b) { return (b + 255) / 256 * 256; };
  SortLayout L{align(sizeof(K) * n), align(sizeof(V) * n), 0};
  cub::DoubleBuffer<K> dk(nullptr, nullptr);
  cub::DoubleBuffer<V> dv(nullptr, nullptr);
  SEAMLESS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, L.cub, dk, dv, n, 0, key_bits, stream));
  return L;
}
}  // namespace cuda_detail

template <class K, class V> std::size_t CudaExec::sort_by_key_temp_bytes(std::int64_t n, int key_bits) const {
  return n <= 1 ? 0 : cuda_detail::sort_layout<K, V>(n, key_bits).total();
}

template <class K, class V> void CudaExec::sort_by_key(K* keys, V* values, std::int64_t n, int key_bits) const {
  if (n <= 1) return;
  // Scratch layout: [alternate keys | alternate values | CUB temp].
  cudaStream_t st = static_cast<cudaStream_t>(stream);
  const cuda_detail::SortLayout L = cuda_detail::sort_layout<K, V>(n, key_bits, st);
  if (temp && temp_bytes < L.total())
    throw Error("CudaExec::sort_by_key: the caller's temp storage has " + std::to_string(temp_bytes) +
                " bytes, the sort of " + std::to_string(n) + " pairs needs " + std::to_string(L.total()) +
                "; size it with sort_by_key_temp_bytes");
  char* s = static_cast<char*>(temp ? temp : cuda_detail::scratch(L.total()));
  std::size_t tmp = L.cub;
  cub::DoubleBuffer<K> dk(keys, reinterpret_cast<K*>(s));
  cub::DoubleBuffer<V> dv(values, reinterpret_cast<V*>(s + L.keys));
  SEAMLESS_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(s + L.keys + L.values, tmp, dk, dv, n, 0, key_bits, st));
  if (dk.Current() != keys) {
    SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(keys, dk.Current(), sizeof(K) * n, cudaMemcpyDeviceToDevice, st));
    SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(values, dv.Current(), sizeof(V) * n, cudaMemcpyDeviceToDevice, st));
  }
}

template <class T, class F, class G> void CudaExec::transform_reduce_into(std::int64_t n, F fn, T* out, G then) const {
  // One wave of as many blocks as fit on the device at once (registers decide): each thread then
  // strides over several elements instead of blocks queueing behind each other.
  constexpr int kThreads = 128;
  static const int resident = [] {
    int per_sm = 0;
    SEAMLESS_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(
        &per_sm, cuda_detail::transform_reduce_kernel<kThreads, T, F, G>, kThreads, 0));
    return std::max(1, per_sm) * cuda_detail::multiprocessors();
  }();
  std::int64_t wanted = std::max<std::int64_t>(1, (n + kThreads - 1) / kThreads);
  int blocks = static_cast<int>(std::min<std::int64_t>(wanted, resident));
  using Local = decltype(fn(std::int64_t{}));
  Local* partial = static_cast<Local*>(cuda_detail::scratch(sizeof(Local) * blocks));
  // The partials (shared scratch) and the counter are one per process: reductions must not run
  // concurrently on two streams.
  cuda_detail::transform_reduce_kernel<kThreads, T><<<blocks, kThreads, 0, static_cast<cudaStream_t>(stream)>>>(
      n, fn, partial, cuda_detail::reduce_counter(), out, then);
  SEAMLESS_CUDA_CHECK_LAUNCH("transform_reduce");
}

template <class T, class F, class G>
void CudaExec::transform_reduce_rounds(std::int64_t n, int rounds, F fn, T* out, G then) const {
  if (rounds <= 0) return;
  constexpr int kThreads = 256;
  auto kernel = cuda_detail::transform_reduce_rounds_kernel<kThreads, T, F, G>;
  // A cooperative launch must fit on the device at once: at most the resident blocks.
  static const int resident = [&] {
    int per_sm = 0;
    SEAMLESS_CUDA_CHECK(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, kThreads, 0));
    return std::max(1, per_sm) * cuda_detail::multiprocessors();
  }();
  std::int64_t wanted = std::max<std::int64_t>(1, (n + kThreads - 1) / kThreads);
  int blocks = static_cast<int>(std::min<std::int64_t>(wanted, resident));
  using W = cuda_detail::RoundWords<decltype(fn(std::int64_t{}))>;
  // The partials (component-major) and, after them, the stop flag, in the shared scratch (one
  // collective at a time).
  const std::size_t flag_at = sizeof(float) * W::kWords * static_cast<std::size_t>(blocks);
  auto* base = static_cast<unsigned char*>(cuda_detail::scratch(flag_at + sizeof(int)));
  float* partial = reinterpret_cast<float*>(base);
  int* stop = reinterpret_cast<int*>(base + flag_at);
  void* args[] = {&n, &rounds, &fn, &partial, &stop, &out, &then};
  SEAMLESS_CUDA_CHECK(cudaLaunchCooperativeKernel(reinterpret_cast<const void*>(kernel), dim3(blocks), dim3(kThreads),
                                                  args, 0, static_cast<cudaStream_t>(stream)));
}

template <class T, class F> T CudaExec::transform_reduce(std::int64_t n, T init, F fn) const {
  if (n <= 0) return init;
  T* total_dev = static_cast<T*>(cuda_detail::result_slot(sizeof(T)));
  CudaExec{}.transform_reduce_into(n, fn, total_dev);  // on the legacy default stream, like the copy
  T total{};
  SEAMLESS_CUDA_CHECK(cudaMemcpy(&total, total_dev, sizeof(T), cudaMemcpyDeviceToHost));
  return init + total;
}

}  // namespace seamless
