// Non-template parts of the CUDA executor.
#include "core/exec_cuda.cuh"

namespace seamless {

void CudaExec::synchronize() const { SEAMLESS_CUDA_CHECK(cudaDeviceSynchronize()); }

namespace cuda_detail {
int max_shared_per_block() {
  static const int bytes = [] {
    int dev = 0, b = 0;
    SEAMLESS_CUDA_CHECK(cudaGetDevice(&dev));
    SEAMLESS_CUDA_CHECK(cudaDeviceGetAttribute(&b, cudaDevAttrMaxSharedMemoryPerBlockOptin, dev));
    return b;
  }();
  return bytes;
}
}  // namespace cuda_detail

int CudaExec::lanes(std::int64_t n, int max_lanes) const {
  // Threads the device holds at once (2048 per multiprocessor on Hopper): fewer elements than
  // that leave multiprocessors idle unless each gets several lanes.
  static const std::int64_t resident = [] {
    int dev = 0, per_sm = 0;
    SEAMLESS_CUDA_CHECK(cudaGetDevice(&dev));
    SEAMLESS_CUDA_CHECK(cudaDeviceGetAttribute(&per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, dev));
    return std::int64_t{per_sm} * cuda_detail::multiprocessors();
  }();
  int g = 1;
  while (2 * g <= max_lanes && g < 32 && n * g < resident) g <<= 1;
  // Groups of 2 or 4 lanes cost more than they give: each group's ballots and shuffles name its
  // own mask, and a warp of 8-16 such groups runs them group after group. From 8 lanes on, the
  // shorter chains win (docs/PERFORMANCE.md).
  return g >= 8 ? g : 1;
}

CudaStream::CudaStream() {
  cudaStream_t s = nullptr;
  cudaEvent_t a = nullptr, b = nullptr;
  SEAMLESS_CUDA_CHECK(cudaStreamCreateWithFlags(&s, cudaStreamNonBlocking));
  SEAMLESS_CUDA_CHECK(cudaEventCreateWithFlags(&a, cudaEventDisableTiming));
  SEAMLESS_CUDA_CHECK(cudaEventCreateWithFlags(&b, cudaEventDisableTiming));
  stream_ = s, joined_ = a, done_ = b;
}

CudaStream::~CudaStream() {
  cudaEventDestroy(static_cast<cudaEvent_t>(joined_));
  cudaEventDestroy(static_cast<cudaEvent_t>(done_));
  cudaStreamDestroy(static_cast<cudaStream_t>(stream_));
}

void CudaStream::after_default() {
  auto e = static_cast<cudaEvent_t>(joined_);
  SEAMLESS_CUDA_CHECK(cudaEventRecord(e, cudaStreamLegacy));
  SEAMLESS_CUDA_CHECK(cudaStreamWaitEvent(static_cast<cudaStream_t>(stream_), e, 0));
}

void CudaStream::before_default() {
  auto e = static_cast<cudaEvent_t>(done_);
  SEAMLESS_CUDA_CHECK(cudaEventRecord(e, static_cast<cudaStream_t>(stream_)));
  SEAMLESS_CUDA_CHECK(cudaStreamWaitEvent(cudaStreamLegacy, e, 0));
}

CudaGraph::~CudaGraph() {
  abort_capture();
  reset();
}

void CudaGraph::begin_capture(const CudaStream& s) {
  if (capturing_) throw Error("CudaGraph::begin_capture: a capture is already open; end or abort it first");
  SEAMLESS_CUDA_CHECK(cudaStreamBeginCapture(static_cast<cudaStream_t>(s.get()), cudaStreamCaptureModeThreadLocal));
  capturing_ = s.get();
}

void CudaGraph::end_capture() {
  if (!capturing_) throw Error("CudaGraph::end_capture: no capture is open (call begin_capture first)");
  cudaGraph_t g = nullptr;
  cudaError_t e = cudaStreamEndCapture(static_cast<cudaStream_t>(capturing_), &g);
  capturing_ = nullptr;
  if (e != cudaSuccess) {
    if (g) cudaGraphDestroy(g);
    detail::throw_cuda_error(e, "cudaStreamEndCapture", __FILE__, __LINE__);
  }
  reset();
  cudaGraphExec_t x = nullptr;
  e = cudaGraphInstantiate(&x, g, 0);
  cudaGraphDestroy(g);
  if (e != cudaSuccess) detail::throw_cuda_error(e, "cudaGraphInstantiate", __FILE__, __LINE__);
  exec_ = x;
}

void CudaGraph::abort_capture() {
  if (!capturing_) return;
  cudaGraph_t g = nullptr;
  cudaStreamEndCapture(static_cast<cudaStream_t>(capturing_), &g);  // invalidated captures end with an error
  if (g) cudaGraphDestroy(g);
  cudaGetLastError();  // clears the error that the failed capture left for the next check
  capturing_ = nullptr;
}

void CudaGraph::launch(const CudaStream& s) const {
  if (!exec_) throw Error("CudaGraph::launch: nothing captured (call begin_capture / end_capture first)");
  SEAMLESS_CUDA_CHECK(cudaGraphLaunch(static_cast<cudaGraphExec_t>(exec_), static_cast<cudaStream_t>(s.get())));
  launched_ = s.get();
}

void CudaGraph::reset() {
  if (!exec_) return;
  if (launched_) cudaStreamSynchronize(static_cast<cudaStream_t>(launched_));
  cudaGraphExecDestroy(static_cast<cudaGraphExec_t>(exec_));
  exec_ = nullptr, launched_ = nullptr;
}

namespace cuda_detail {

namespace {
// A process-lifetime device buffer that only grows. Freed at exit (the error, if the CUDA runtime
// is already unloading, is of no consequence), so that compute-sanitizer's leak check reports only
// real leaks.
struct GrowingBlock {
  void* ptr = nullptr;
  std::size_t size = 0;
  void* at_least(std::size_t bytes, std::size_t reserve) {
    if (bytes > size) {
      if (ptr) SEAMLESS_CUDA_CHECK(cudaFree(ptr));
      size = reserve;
      SEAMLESS_CUDA_CHECK(cudaMalloc(&ptr, size));
    }
    return ptr;
  }
  ~GrowingBlock() {
    if (ptr) cudaFree(ptr);
  }
};
}  // namespace

void* scratch(std::size_t bytes) {
  static GrowingBlock block;
  return block.at_least(bytes, bytes + bytes / 2);
}

void* result_slot(std::size_t bytes) {
  static GrowingBlock block;
  return block.at_least(bytes, bytes);
}

unsigned* reduce_counter() {
  static GrowingBlock block;
  if (!block.ptr)
    SEAMLESS_CUDA_CHECK(cudaMemset(block.at_least(sizeof(unsigned), sizeof(unsigned)), 0, sizeof(unsigned)));
  return static_cast<unsigned*>(block.ptr);
}

int multiprocessors() {
  static int count = [] {
    int dev = 0, n = 0;
    SEAMLESS_CUDA_CHECK(cudaGetDevice(&dev));
    SEAMLESS_CUDA_CHECK(cudaDeviceGetAttribute(&n, cudaDevAttrMultiProcessorCount, dev));
    return n;
  }();
  return count;
}

}  // namespace cuda_detail
}  // namespace seamless
