// The OpenMP executor. Include only from *_cpu.cpp instantiation files and CPU-only code.
#pragma once
#include <omp.h>

#include <algorithm>
#include <cstring>
#include <numeric>
#include <vector>

#include "core/exec.hpp"

namespace seamless {

// Every primitive of core/exec.hpp's list, with the forms the kernels call.
static_assert(Executor<CpuExec>);

template <class F> void CpuExec::for_each(std::int64_t n, F fn) const {
  // Small ranges are not worth waking the thread team.
  if (n < 2048) {
    for (std::int64_t i = 0; i < n; ++i) fn(i);
    return;
  }
  // Chunks of 1024 dealt to the threads in turn, not one contiguous share each: a kernel's cost
  // varies over its range (the raycast's rays through the far wall in the image's top rows cost
  // several times those that end on a desk below), and contiguous halves left one of 2 threads
  // waiting (docs/PERFORMANCE.md, "for_each's OpenMP schedule"). The chunk keeps a thread's
  // elements contiguous for the cache; each element is independent, so results do not change.
#pragma omp parallel for schedule(static, 1024)
  for (std::int64_t i = 0; i < n; ++i) fn(i);
}

template <class F> void CpuExec::for_each_grouped(std::int64_t n, int, F fn) const {
  // A thread already walks several elements; the neighbour loops inside stay whole (Lanes{}:
  // lane 0 of 1, so sum and rank are the identity and the order of every sum is the loop's).
  for_each(n, [&](std::int64_t i) { fn(i, Lanes{}); });
}

// Phase after phase, each a parallel loop (the end of the loop is the barrier).
template <class F>
void CpuExec::for_each_phases(int phases, const std::int64_t* begin, const std::int64_t* end, F fn) const {
  for (int p = 0; p < phases; ++p) {
    const std::int64_t b = begin[p];
    for_each(end[p] - b, [&](std::int64_t i) { fn(p, b + i); });
  }
}

template <class F, class... T>
void CpuExec::for_each_phases_staged(int phases, const std::int64_t* begin, const std::int64_t* end, F fn,
                                     Staged<T>... arrays) const {
  for_each_phases(phases, begin, end, [&](int p, std::int64_t i) { fn(p, i, arrays.ptr...); });
}

template <class T> T CpuExec::exclusive_scan(const T* in, T* out, std::int64_t n) const {
  T sum{};
  for (std::int64_t i = 0; i < n; ++i) {
    T v = in[i];  // in may alias out
    out[i] = sum;
    sum = sum + v;
  }
  return sum;
}

// LSD radix sort, 8 bits a pass: stable, O(n) per pass, like the GPU's radix sort.
template <class K, class V> void CpuExec::sort_by_key(K* keys, V* values, std::int64_t n, int key_bits) const {
  if (n <= 1) return;
  std::vector<K> k2(static_cast<std::size_t>(n));
  std::vector<V> v2(static_cast<std::size_t>(n));
  K* ks = keys;
  V* vs = values;
  K* kd = k2.data();
  V* vd = v2.data();
  for (int shift = 0; shift < key_bits; shift += 8) {
    std::int64_t count[257] = {0};
    for (std::int64_t i = 0; i < n; ++i) ++count[((ks[i] >> shift) & 0xFF) + 1];
    for (int b = 0; b < 256; ++b) count[b + 1] += count[b];
    for (std::int64_t i = 0; i < n; ++i) {
      std::int64_t dst = count[(ks[i] >> shift) & 0xFF]++;
      kd[dst] = ks[i];
      vd[dst] = vs[i];
    }
    std::swap(ks, kd);
    std::swap(vs, vd);
  }
  if (ks != keys) {
    std::memcpy(keys, ks, sizeof(K) * n);
    std::memcpy(values, vs, sizeof(V) * n);
  }
}

// Per-thread partial sums combined in thread order: deterministic for a fixed thread count. Thread
// t of T takes one contiguous share, the first n % T threads one element more (OpenMP's static
// schedule as libgomp deals it, written out so that reduce_ranges' callers get the same shares).
template <class T, class F> T CpuExec::reduce_ranges(std::int64_t n, T init, F add) const {
  const int threads = n < 2048 ? 1 : omp_get_max_threads();
  std::vector<T> partial(static_cast<std::size_t>(threads), T{});
#pragma omp parallel num_threads(threads)
  {
    const std::int64_t t = omp_get_thread_num(), team = omp_get_num_threads();
    const std::int64_t q = n / team, r = n % team;
    const std::int64_t begin = t * q + std::min(t, r), end = begin + q + (t < r ? 1 : 0);
    T local{};
    add(begin, end, local);
    partial[t] = local;
  }
  T sum = init;
  for (const T& p : partial) sum = sum + p;
  return sum;
}

template <class T, class F> T CpuExec::transform_reduce(std::int64_t n, T init, F fn) const {
  return reduce_ranges(n, init, [&](std::int64_t begin, std::int64_t end, T& local) {
    for (std::int64_t i = begin; i < end; ++i) local = local + fn(i);
  });
}

template <class T, class F, class G> void CpuExec::transform_reduce_into(std::int64_t n, F fn, T* out, G then) const {
  *out = transform_reduce(n, T{}, fn);
  then();
}

template <class T, class F, class G>
void CpuExec::reduce_ranges_rounds(std::int64_t n, int rounds, F add, T* out, G then) const {
  for (int r = 0; r < rounds; ++r) {
    *out = reduce_ranges(n, T{}, add);
    if (then(r, *out)) return;
  }
}

template <class T, class F, class G>
void CpuExec::transform_reduce_rounds(std::int64_t n, int rounds, F fn, T* out, G then) const {
  reduce_ranges_rounds(
      n, rounds,
      [&](std::int64_t begin, std::int64_t end, T& local) {
        for (std::int64_t i = begin; i < end; ++i) local = local + fn(i);
      },
      out, then);
}

}  // namespace seamless
