#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <unordered_map>
#include <unordered_set>

#include <sys/mman.h>
#include <unistd.h>

#include "core/buffer.hpp"
#include "core/cuda_check.hpp"
#include "core/error.hpp"

namespace seamless::memory {

namespace {
// Live allocations and their sizes, for the memory statistics the pipeline reports.
struct Ledger {
  std::mutex mutex;
  std::unordered_map<void*, std::size_t> sizes;
  std::unordered_set<void*> pinned;  // host allocations from cudaMallocHost (freed by cudaFreeHost)
  std::unordered_set<void*> mapped;  // host allocations from mmap (allocate_zeroed; freed by munmap)
  std::size_t bytes[2] = {0, 0};
  std::size_t peak[2] = {0, 0};
};
Ledger& ledger() {
  static Ledger l;
  return l;
}
// How a live allocation was made, which says how it is freed.
enum class Kind { plain, pinned, mapped };
void record(void* p, std::size_t bytes, Device d, Kind k = Kind::plain) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  l.sizes[p] = bytes;
  const int i = static_cast<int>(d);
  l.bytes[i] += bytes;
  l.peak[i] = std::max(l.peak[i], l.bytes[i]);
  if (k == Kind::pinned) l.pinned.insert(p);
  if (k == Kind::mapped) l.mapped.insert(p);
}
// Forgets p; returns how it was allocated and its size.
struct Forgotten {
  Kind kind = Kind::plain;
  std::size_t bytes = 0;
};
Forgotten forget(void* p, Device d) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  auto it = l.sizes.find(p);
  if (it == l.sizes.end()) return {};
  const std::size_t bytes = it->second;
  l.bytes[static_cast<int>(d)] -= bytes;
  l.sizes.erase(it);
  if (l.pinned.erase(p) > 0) return {Kind::pinned, bytes};
  return {l.mapped.erase(p) > 0 ? Kind::mapped : Kind::plain, bytes};
}
bool is_mapped(void* p) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  return l.mapped.count(p) > 0;
}
std::size_t page_rounded(std::size_t bytes) {
  static const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
  return (bytes + page - 1) / page * page;
}
[[noreturn]] void out_of_memory(std::size_t bytes, Device d) {
  throw Error("out of " + std::string(device_name(d)) + " memory allocating " + std::to_string(bytes >> 20) +
              " MiB (reduce the volume size, hash capacity or particle count in the config)");
}
constexpr std::size_t kAlign = 64;
}  // namespace

void* allocate(std::size_t bytes, Device d) {
  if (bytes == 0) return nullptr;
  void* p = nullptr;
  if (d == Device::CPU) {
    p = std::aligned_alloc(kAlign, (bytes + kAlign - 1) / kAlign * kAlign);
    if (!p) out_of_memory(bytes, d);
  } else {
#if SEAMLESS_HAS_CUDA
    cudaError_t e = cudaMalloc(&p, bytes);
    if (e == cudaErrorMemoryAllocation) {
      cudaGetLastError();
      out_of_memory(bytes, d);
    }
    SEAMLESS_CUDA_CHECK(e);
#else
    throw Error("CUDA allocation requested in a build without CUDA");
#endif
  }
  record(p, bytes, d);
  return p;
}

void* allocate_pinned(std::size_t bytes) {
  if (bytes == 0) return nullptr;
#if SEAMLESS_HAS_CUDA
  void* p = nullptr;
  if (cudaMallocHost(&p, bytes) == cudaSuccess) {
    record(p, bytes, Device::CPU, Kind::pinned);
    return p;
  }
  cudaGetLastError();  // no GPU or no page-locked memory left: ordinary memory still works
#endif
  return allocate(bytes, Device::CPU);
}

bool is_pinned(const void* p) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  return l.pinned.count(const_cast<void*>(p)) > 0;
}

void* allocate_zeroed(std::size_t bytes, Device d) {
  if (bytes == 0) return nullptr;
  if (d != Device::CPU) {
    void* p = allocate(bytes, d);
    fill_zero(p, d, bytes);
    return p;
  }
  void* p = mmap(nullptr, page_rounded(bytes), PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) out_of_memory(bytes, d);
  // Huge pages where the system gives them on request: a 2 MiB page is zero-filled in one fault
  // where 4 KiB pages take 512 (the voxel pool is written block by block as the scan grows).
  madvise(p, page_rounded(bytes), MADV_HUGEPAGE);
  record(p, bytes, d, Kind::mapped);
  return p;
}

void* grow_zeroed(void* p, std::size_t old_bytes, std::size_t new_bytes, Device d) {
  if (!p) return allocate_zeroed(new_bytes, d);
  if (d == Device::CPU && is_mapped(p)) {
    // The kernel moves the pages (a page-table update, no copy) and zero-fills the new ones when
    // they are first written.
    void* q = mremap(p, page_rounded(old_bytes), page_rounded(new_bytes), MREMAP_MAYMOVE);
    if (q == MAP_FAILED) out_of_memory(new_bytes, d);
    forget(p, d);
    record(q, new_bytes, d, Kind::mapped);
    return q;
  }
  void* q = allocate_zeroed(new_bytes, d);
  copy(q, d, p, d, old_bytes);
  release(p, d);
  return q;
}

void release(void* p, Device d) noexcept {
  if (!p) return;
  const Forgotten f = forget(p, d);
  if (f.kind == Kind::mapped) {
    munmap(p, page_rounded(f.bytes));
    return;
  }
#if SEAMLESS_HAS_CUDA
  if (f.kind == Kind::pinned) {
    cudaFreeHost(p);
    return;
  }
#endif
  if (d == Device::CPU) {
    std::free(p);
    return;
  }
#if SEAMLESS_HAS_CUDA
  cudaFree(p);
#endif
}

void copy(void* dst, Device dst_dev, const void* src, Device src_dev, std::size_t bytes) {
  if (bytes == 0) return;
  if (dst_dev == Device::CPU && src_dev == Device::CPU) {
    std::memcpy(dst, src, bytes);
    return;
  }
#if SEAMLESS_HAS_CUDA
  SEAMLESS_CUDA_CHECK(cudaMemcpy(dst, src, bytes, cudaMemcpyDefault));
#else
  throw Error("CUDA copy requested in a build without CUDA");
#endif
}

void copy_async(void* dst, Device dst_dev, const void* src, Device src_dev, std::size_t bytes, void* stream) {
  if (bytes == 0) return;
  if (dst_dev == Device::CPU && src_dev == Device::CPU) {
    std::memcpy(dst, src, bytes);
    return;
  }
#if SEAMLESS_HAS_CUDA
  cudaStream_t s = stream ? static_cast<cudaStream_t>(stream) : cudaStreamLegacy;
  SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyDefault, s));
#else
  (void)stream;
  throw Error("CUDA copy requested in a build without CUDA");
#endif
}

void fill_zero(void* p, Device d, std::size_t bytes) {
  if (bytes == 0) return;
  if (d == Device::CPU) {
    std::memset(p, 0, bytes);
    return;
  }
#if SEAMLESS_HAS_CUDA
  SEAMLESS_CUDA_CHECK(cudaMemset(p, 0, bytes));
#endif
}

std::size_t bytes_in_use(Device d) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  return l.bytes[static_cast<int>(d)];
}

std::size_t peak_bytes(Device d) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  return l.peak[static_cast<int>(d)];
}

void reset_peak(Device d) {
  Ledger& l = ledger();
  std::lock_guard lock(l.mutex);
  l.peak[static_cast<int>(d)] = l.bytes[static_cast<int>(d)];
}

}  // namespace seamless::memory
