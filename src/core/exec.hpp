// Executors: the one place where the two backends differ. Every computation is written once: the
// per-element math as SEAMLESS_HD inline functions (core/hd.hpp) in headers under kernels/, and each
// kernel family as a template over an executor, instantiated twice by two small files: one compiled
// as C++ with the OpenMP executor (exec_cpu.hpp), one compiled by nvcc with the CUDA executor
// (exec_cuda.cuh, collectives from CUB). No algorithm is written twice; the same tests run on both
// backends, and the Parity tests (ctest label gpu) compare their results on the same inputs. Memory
// is a Buffer<T> (core/buffer.hpp) owning one allocation on one device; kernels see plain views
// (core/view.hpp), transfers are explicit, and Eigen stays on the host side.
//
// A kernel family is a template over the executor type and uses only:
//   ex.for_each(n, fn)                   fn(i) for i in [0, n), in parallel
//   ex.exclusive_scan(in, out, n)        out[i] = sum of in[0..i); returns the total (to the host)
//   ex.sort_by_key(keys, values, n, b)   stable sort of (key, value) pairs by the low b bits of key
//   ex.transform_reduce(n, init, fn)     init + sum of fn(i); T needs operator+ (returned to host);
//                                        fn may return a narrower type U with T + U and U + U
//                                        (per-thread partial sums in U, the total in T)
//   ex.transform_reduce_into(n, fn, out[, then])
//                                        *out = sum of fn(i), out on ex.device: no host round trip, so
//                                        a loop of kernels (ICP's Gauss-Newton steps) never waits;
//                                        then(), if given, runs once on the device after *out is
//                                        written (in the same launch on CUDA)
//   ex.transform_reduce_rounds(n, rounds, fn, out, then)
//                                        up to `rounds` rounds of: *out = sum of fn(i), then
//                                        bool then(round, *out) on the device; a round's fn sees
//                                        what the previous round's then wrote, and the rounds stop
//                                        once then returns true (a Gauss-Newton loop in one
//                                        launch); fn returns a struct of floats, summed component
//                                        by component, widened into T (T{} + sum) once a round
//   ex.for_each_grouped(n, max_lanes, fn)
//                                        fn(i, lanes) for i in [0, n), each i by a group of
//                                        lanes.size lanes (a power of two <= max_lanes, chosen
//                                        by the executor: 1 on the CPU, 1 or >= 8 on CUDA) that split i's work and
//                                        combine it with lanes.sum / lanes.rank (Lanes below)
//   ex.for_each_grouped(n, max_lanes, fn, MinBlocks<B>{})
//                                        the same, with at least B blocks of the executor's
//                                        threads resident per multiprocessor (CUDA: a launch
//                                        bound, which caps the kernel's registers; CPU: ignored)
//   ex.lanes(n, max_lanes)               the group size for_each_grouped(n, max_lanes, ...) uses
//   ex.for_each_phases(phases, begin, end, fn)
//                                        fn(p, i) for i in [begin[p], end[p]), phase after phase:
//                                        phase p + 1 sees every write of phase p (a colour-
//                                        sequenced Gauss-Seidel sweep); begin, end on the host
//   ex.for_each_phases_staged(phases, begin, end, fn, Staged<T>{ptr, count}...)
//                                        for_each_phases with fn(p, i, T* a...): a is ptr or a
//                                        copy of its count elements in fast memory (CUDA: the
//                                        block's shared memory) for the whole sweep, written
//                                        back at the end unless T is const (see Staged below)
//   ex.synchronize()
//   ex.device                            the Device it runs on (a constant)
// plus the SEAMLESS_HD atomics in core/atomics.hpp. Pointers passed in live on ex.device.
// The concept Executor below states this list; both backends are checked against it
// (static_assert in core/exec_cpu.hpp and core/exec_cuda.cuh).
//
// CpuExec's members are defined in core/exec_cpu.hpp (OpenMP), CudaExec's in core/exec_cuda.cuh
// (CUDA + CUB). A kernel family is a class template `template <Executor Exec> struct Name`
// whose kernels are static member functions, declared in the family's header and defined in its
// .inl; each backend instantiates the whole family with one line
// (`template struct seamless::kernels::Name<seamless::CpuExec>;`). Host code includes only this
// header and the family's, and picks the backend with with_exec():
//   with_exec(dev, [&]<class E>(const E& ex) { kernels::Name<E>::kernel(ex, ...); });
#pragma once
#include <concepts>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "core/device.hpp"
#include "core/error.hpp"
#include "core/hd.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

// The default `then` of transform_reduce_into: nothing.
struct NoThen {
  SEAMLESS_HD void operator()() const {}
};

// The lanes that work on one element of for_each_grouped: `size` (a power of two <= 32)
// consecutive threads of a warp on CUDA, one thread on the CPU. A kernel splits the element's
// loops over them (k = lane, lane + size, ...) and combines the partial results with sum and
// rank. Every lane of a group must call these together, with the same loop bounds (the group's
// control flow must be uniform there); on the CPU they are the identity.
struct Lanes {
  int lane = 0, size = 1;
  unsigned mask = 1u;  // the group's lanes within the warp (CUDA)
  int first = 0;       // the group's first lane within the warp (CUDA)

  // The sum over the group's lanes of v (T trivially copyable, a multiple of 4 bytes, with
  // operator+), in every lane, bit-identical in all of them: a butterfly of shuffles word by
  // word, adding neighbours, then pairs, ... (a tree: the same order for a given size).
  template <class T> SEAMLESS_HD T sum(T v) const {
#if defined(__CUDA_ARCH__)
    static_assert(sizeof(T) % 4 == 0, "Lanes::sum shuffles 4-byte words");
    constexpr int kWords = static_cast<int>(sizeof(T) / 4);
    for (int o = 1; o < size; o <<= 1) {
      unsigned w[kWords];
      memcpy(w, &v, sizeof(T));
      for (int k = 0; k < kWords; ++k) w[k] = __shfl_xor_sync(mask, w[k], o);
      T u;
      memcpy(&u, w, sizeof(T));
      v = v + u;  // a + b == b + a bit for bit, so every lane ends with the same bits
    }
#endif
    return v;
  }

  // Stream compaction within the group: the number of lanes below this one whose p is true;
  // *total = the number of lanes whose p is true. Appending in lane order keeps the order of a
  // one-lane loop that visits the same items.
  SEAMLESS_HD int rank(bool p, int* total) const {
#if defined(__CUDA_ARCH__)
    // One lane: no ballot. Each thread of the warp would name a different one-lane mask, and
    // such syncs run the warp's threads one after another (several times slower than a plain
    // loop in find_neighbors, docs/PERFORMANCE.md).
    if (size == 1) {
      *total = p ? 1 : 0;
      return 0;
    }
    const unsigned b = (__ballot_sync(mask, p) & mask) >> first;
    *total = __popc(b);
    return __popc(b & ((1u << lane) - 1u));
#else
    *total = p ? 1 : 0;
    return 0;
#endif
  }
};

// An array that for_each_phases_staged may hold in fast memory for a sweep: count elements from
// ptr (T trivially copyable; const T = read only, not written back). During the sweep the phase
// function must reach the array only through the pointer it is handed (not through ptr), nothing
// else may write it, and staged arrays must not overlap. The executor stages the arrays it can,
// in argument order while they fit (so the caller lists them most valuable first), and hands the
// others' ptr: the results are the same bit for bit either way (the same arithmetic on the same
// values in the same order; only where the values live differs).
template <class T> struct Staged {
  T* ptr = nullptr;
  std::int64_t count = 0;
};

// for_each_grouped's optional occupancy request (see the list above); B = 0: none.
template <int B> struct MinBlocks {};

struct CpuExec {
  static constexpr Device device = Device::CPU;
  // sort_by_key allocates its own buffers on the CPU (see CudaExec::temp).
  template <class K, class V> std::size_t sort_by_key_temp_bytes(std::int64_t, int = 0) const { return 0; }
  template <class F> void for_each(std::int64_t n, F fn) const;
  template <class T> T exclusive_scan(const T* in, T* out, std::int64_t n) const;
  template <class K, class V> void sort_by_key(K* keys, V* values, std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class T, class F> T transform_reduce(std::int64_t n, T init, F fn) const;
  // CPU only: transform_reduce's sum with each thread's share handed over whole, add(begin, end,
  // local) adding elements begin .. end - 1 into local in order (a vector loop can then take them
  // several at a time and still form transform_reduce's sums bit for bit).
  template <class T, class F> T reduce_ranges(std::int64_t n, T init, F add) const;
  // CPU only: transform_reduce_rounds' rounds, each round's sum formed by reduce_ranges(n, T{}, add).
  template <class T, class F, class G>
  void reduce_ranges_rounds(std::int64_t n, int rounds, F add, T* out, G then) const;
  template <class T, class F, class G = NoThen>
  void transform_reduce_into(std::int64_t n, F fn, T* out, G then = {}) const;
  template <class T, class F, class G>
  void transform_reduce_rounds(std::int64_t n, int rounds, F fn, T* out, G then) const;
  // One thread per element on the CPU: the groups are single lanes.
  int lanes(std::int64_t, int) const { return 1; }
  template <class F> void for_each_grouped(std::int64_t n, int max_lanes, F fn) const;
  template <int B, class F> void for_each_grouped(std::int64_t n, int max_lanes, F fn, MinBlocks<B>) const {
    for_each_grouped(n, max_lanes, fn);
  }
  template <class F> void for_each_phases(int phases, const std::int64_t* begin, const std::int64_t* end, F fn) const;
  // The CPU's caches do the staging: fn gets every array's ptr.
  template <class F, class... T>
  void for_each_phases_staged(int phases, const std::int64_t* begin, const std::int64_t* end, F fn,
                              Staged<T>... arrays) const;
  void synchronize() const {}
};

struct CudaExec {
  static constexpr Device device = Device::CUDA;
  // Optional, for launches captured into a CUDA graph (CudaGraph below): the stream that for_each
  // and sort_by_key launch on (a cudaStream_t; null = the legacy default stream, which cannot be
  // captured), and caller-owned temporary storage for sort_by_key (null = the shared scratch,
  // which a later, larger collective may reallocate under a captured graph). The collectives that
  // return a result to the host stay on the legacy default stream.
  void* stream = nullptr;
  void* temp = nullptr;
  std::size_t temp_bytes = 0;
  // Bytes of temp that sort_by_key needs for n pairs.
  template <class K, class V> std::size_t sort_by_key_temp_bytes(std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class F> void for_each(std::int64_t n, F fn) const;
  template <class T> T exclusive_scan(const T* in, T* out, std::int64_t n) const;
  template <class K, class V> void sort_by_key(K* keys, V* values, std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class T, class F> T transform_reduce(std::int64_t n, T init, F fn) const;
  template <class T, class F, class G = NoThen>
  void transform_reduce_into(std::int64_t n, F fn, T* out, G then = {}) const;
  template <class T, class F, class G>
  void transform_reduce_rounds(std::int64_t n, int rounds, F fn, T* out, G then) const;
  // Lanes per element: the smallest power of two that puts n x lanes threads on the device at
  // once (so that a small n still fills every multiprocessor), at most max_lanes (how far the
  // caller's per-element work splits usefully), at least 1. Defined in core/exec_cuda.cu.
  int lanes(std::int64_t n, int max_lanes) const;
  template <class F> void for_each_grouped(std::int64_t n, int max_lanes, F fn) const;
  template <int B, class F> void for_each_grouped(std::int64_t n, int max_lanes, F fn, MinBlocks<B>) const;
  template <class F> void for_each_phases(int phases, const std::int64_t* begin, const std::int64_t* end, F fn) const;
  // Where for_each_phases runs the sweep in one block, the arrays that fit (in argument order)
  // live in the block's dynamic shared memory for the sweep: a phase then reads and writes them
  // without a round trip to L2 (most of a small cloth's phase is such round trips: docs/PERFORMANCE.md).
  template <class F, class... T>
  void for_each_phases_staged(int phases, const std::int64_t* begin, const std::int64_t* end, F fn,
                              Staged<T>... arrays) const;
  void synchronize() const;
};

// The executor's primitives (the list at the top of this file), checked on small probe functors:
// only the calls' forms (arguments and results) are checked here, not what they compute (that is
// tests/core). A kernel family is a template over an Executor.
namespace exec_probe {
struct Index {  // for_each
  SEAMLESS_HD void operator()(std::int64_t) const {}
};
struct Value {  // transform_reduce*: a number per element
  SEAMLESS_HD float operator()(std::int64_t) const { return 0.f; }
};
struct Round {  // transform_reduce_rounds' then: true = stop
  SEAMLESS_HD bool operator()(int, const float&) const { return true; }
};
struct Grouped {  // for_each_grouped
  SEAMLESS_HD void operator()(std::int64_t, const Lanes&) const {}
};
struct Phase {  // for_each_phases
  SEAMLESS_HD void operator()(int, std::int64_t) const {}
};
struct StagedPhase {  // for_each_phases_staged with one float array
  SEAMLESS_HD void operator()(int, std::int64_t, float*) const {}
};
}  // namespace exec_probe

template <class E>
concept Executor = requires(const E& ex, std::int64_t n, int k, const int* in, int* out, unsigned* keys, float* sum,
                            const std::int64_t* begin, const std::int64_t* end) {
  typename std::integral_constant<Device, E::device>;  // a constant: kernels branch on it
  ex.for_each(n, exec_probe::Index{});
  { ex.exclusive_scan(in, out, n) } -> std::same_as<int>;
  ex.sort_by_key(keys, out, n, k);
  ex.sort_by_key(keys, out, n);
  { ex.transform_reduce(n, 0.0, exec_probe::Value{}) } -> std::same_as<double>;
  ex.transform_reduce_into(n, exec_probe::Value{}, sum);
  ex.transform_reduce_into(n, exec_probe::Value{}, sum, NoThen{});
  ex.transform_reduce_rounds(n, k, exec_probe::Value{}, sum, exec_probe::Round{});
  ex.for_each_grouped(n, k, exec_probe::Grouped{});
  ex.for_each_grouped(n, k, exec_probe::Grouped{}, MinBlocks<2>{});
  { ex.lanes(n, k) } -> std::same_as<int>;
  ex.for_each_phases(k, begin, end, exec_probe::Phase{});
  ex.for_each_phases_staged(k, begin, end, exec_probe::StagedPhase{}, Staged<float>{sum, n});
  ex.synchronize();
};

#if SEAMLESS_HAS_CUDA
// A CUDA stream of its own (non-blocking) and the ordering with the legacy default stream, where
// uploads, downloads and other code run: after_default() makes the stream wait for what was
// issued there so far, before_default() makes the default stream wait for what was issued here,
// both without a host synchronisation. Defined in core/exec_cuda.cu.
class CudaStream {
 public:
  CudaStream();
  ~CudaStream();
  CudaStream(const CudaStream&) = delete;
  CudaStream& operator=(const CudaStream&) = delete;
  void* get() const { return stream_; }  // cudaStream_t
  void after_default();
  void before_default();

 private:
  void *stream_ = nullptr, *joined_ = nullptr, *done_ = nullptr;  // cudaStream_t, cudaEvent_t x2
};

// A sequence of launches on a CudaStream recorded once (begin_capture ... end_capture: the
// launches are recorded, not run) and replayed as one graph launch (Graph Management, CUDA
// programming guide). Everything the launches point to must stay where it was while the graph
// is used. Capture is thread-local: a synchronising call of this thread during capture fails.
class CudaGraph {
 public:
  CudaGraph() = default;
  ~CudaGraph();
  CudaGraph(const CudaGraph&) = delete;
  CudaGraph& operator=(const CudaGraph&) = delete;
  void begin_capture(const CudaStream& s);
  void end_capture();    // instantiates the graph (replacing the one held)
  void abort_capture();  // after an error inside the capture: ends it and drops what was recorded
  void launch(const CudaStream& s) const;
  bool ready() const { return exec_ != nullptr; }
  void reset();  // waits for the last launch, then drops the graph

 private:
  // cudaStream_t being captured, cudaGraphExec_t, cudaStream_t of the last launch
  void *capturing_ = nullptr, *exec_ = nullptr;
  mutable void* launched_ = nullptr;
};
#endif

// Calls fn(executor) with the executor for device d.
template <class F> decltype(auto) with_exec(Device d, F&& fn) {
#if SEAMLESS_HAS_CUDA
  if (d == Device::CUDA) return fn(CudaExec{});
#else
  if (d == Device::CUDA) throw Error("the CUDA backend is not built into this binary");
#endif
  return fn(CpuExec{});
}

}  // namespace seamless
