// Executors: the one place where the two backends differ (see DESIGN, "One kernel, two backends").
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
//   ex.synchronize()
// plus the SEAMLESS_HD atomics in core/atomics.hpp. Pointers passed in live on ex.device.
//
// CpuExec's members are defined in core/exec_cpu.hpp (OpenMP), CudaExec's in core/exec_cuda.cuh
// (CUDA + CUB). Host code includes only this header and calls kernel templates through
// with_exec(); the kernel's .inl is compiled once per backend by two tiny instantiation files.
#pragma once
#include <cstddef>
#include <cstdint>

#include "core/device.hpp"
#include "core/error.hpp"
#include "core/hd.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

// The default `then` of transform_reduce_into: nothing.
struct NoThen {
  SEAMLESS_HD void operator()() const {}
};

struct CpuExec {
  static constexpr Device device = Device::CPU;
  // sort_by_key allocates its own buffers on the CPU (see CudaExec::temp).
  template <class K, class V> std::size_t sort_by_key_temp_bytes(std::int64_t, int = 0) const { return 0; }
  template <class F> void for_each(std::int64_t n, F fn) const;
  template <class T> T exclusive_scan(const T* in, T* out, std::int64_t n) const;
  template <class K, class V> void sort_by_key(K* keys, V* values, std::int64_t n, int key_bits = 8 * sizeof(K)) const;
  template <class T, class F> T transform_reduce(std::int64_t n, T init, F fn) const;
  template <class T, class F, class G = NoThen> void transform_reduce_into(std::int64_t n, F fn, T* out, G then = {}) const;
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
  template <class T, class F, class G = NoThen> void transform_reduce_into(std::int64_t n, F fn, T* out, G then = {}) const;
  void synchronize() const;
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
