// Buffer<T>: owns one allocation on one device (RAII, move-only, no managed memory). Transfers are
// explicit: copy_from / to_host. Image<T> is a Buffer with a width and height.
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/device.hpp"
#include "core/view.hpp"

namespace seamless {

namespace memory {
void* allocate(std::size_t bytes, Device d);  // throws Error naming the size when out of memory
void release(void* p, Device d) noexcept;
void copy(void* dst, Device dst_dev, const void* src, Device src_dev, std::size_t bytes);
// Page-locked host memory (cudaMallocHost), so that host-device copies run at full PCIe speed and
// can be asynchronous; ordinary host memory where CUDA is not built or no GPU is usable.
void* allocate_pinned(std::size_t bytes);
bool is_pinned(const void* p);  // allocated by allocate_pinned and actually page-locked
// A copy queued on a CUDA stream (null: the legacy default stream); returns before it is done
// when the host side is page-locked, so that memory must stay untouched until the stream gets
// there. Host-to-host copies are plain memcpy.
void copy_async(void* dst, Device dst_dev, const void* src, Device src_dev, std::size_t bytes, void* stream = nullptr);
void fill_zero(void* p, Device d, std::size_t bytes);
// Zeroed memory that grow_zeroed extends without a copy where it can: on the host, anonymous pages
// (mmap) that the kernel zero-fills when they are first written, so nothing is cleared up front,
// and that mremap extends in place of a copy; on CUDA, cudaMalloc and cudaMemset.
void* allocate_zeroed(std::size_t bytes, Device d);
// p (from allocate or allocate_zeroed, old_bytes long) grown to new_bytes >= old_bytes: the first
// old_bytes kept, the rest zero. Returns the new address; p is no longer valid.
void* grow_zeroed(void* p, std::size_t old_bytes, std::size_t new_bytes, Device d);
std::size_t bytes_in_use(Device d);  // live bytes allocated through Buffer on this device
std::size_t peak_bytes(Device d);    // the most bytes_in_use(d) has been since the start or reset_peak(d)
void reset_peak(Device d);           // the peak starts again from the bytes in use now
}  // namespace memory

template <class T> class Buffer {
  static_assert(std::is_trivially_copyable_v<T>, "Buffer holds plain data only");

 public:
  Buffer() = default;
  Buffer(std::int64_t n, Device d) : device_(d), size_(n) {
    if (n > 0) data_ = static_cast<T*>(memory::allocate(sizeof(T) * n, d));
  }
  // Host memory that is page-locked when a GPU is usable (memory::allocate_pinned): for data that
  // is uploaded often, such as camera frames.
  static Buffer pinned_host(std::int64_t n) {
    Buffer b;
    b.size_ = n;
    if (n > 0) b.data_ = static_cast<T*>(memory::allocate_pinned(sizeof(T) * n));
    return b;
  }
  static Buffer from_host(const std::vector<T>& v, Device d) {
    Buffer b(static_cast<std::int64_t>(v.size()), d);
    b.copy_from_host(v.data(), b.size());
    return b;
  }
  ~Buffer() { memory::release(data_, device_); }
  Buffer(Buffer&& o) noexcept { swap(o); }
  Buffer& operator=(Buffer&& o) noexcept {
    Buffer tmp(std::move(o));
    swap(tmp);
    return *this;
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;

  T* data() const { return data_; }
  std::int64_t size() const { return size_; }
  std::size_t bytes() const { return sizeof(T) * static_cast<std::size_t>(size_); }
  Device device() const { return device_; }
  View<T> view() const { return {data_, size_}; }
  View<const T> cview() const { return {data_, size_}; }

  void zero() { memory::fill_zero(data_, device_, bytes()); }
  // n zero elements that grow_zeroed can extend without copying them (memory::allocate_zeroed).
  static Buffer zeros(std::int64_t n, Device d) {
    Buffer b;
    b.device_ = d, b.size_ = n;
    if (n > 0) b.data_ = static_cast<T*>(memory::allocate_zeroed(sizeof(T) * n, d));
    return b;
  }
  // Grows to n >= size() elements, keeping the contents; the new elements are zero.
  void grow_zeroed(std::int64_t n) {
    if (n <= size_) return;
    data_ = static_cast<T*>(memory::grow_zeroed(data_, bytes(), sizeof(T) * n, device_));
    size_ = n;
  }
  void copy_from_host(const T* src, std::int64_t n) { memory::copy(data_, device_, src, Device::CPU, sizeof(T) * n); }
  void copy_from(const Buffer& o) { memory::copy(data_, device_, o.data_, o.device_, std::min(bytes(), o.bytes())); }
  // memory::copy_async's rules: o must stay unchanged until the stream has done the copy.
  void copy_from_async(const Buffer& o, void* stream = nullptr) {
    memory::copy_async(data_, device_, o.data_, o.device_, std::min(bytes(), o.bytes()), stream);
  }
  std::vector<T> to_host() const {
    std::vector<T> v(static_cast<std::size_t>(size_));
    memory::copy(v.data(), Device::CPU, data_, device_, bytes());
    return v;
  }
  Buffer clone(Device d) const {
    Buffer b(size_, d);
    b.copy_from(*this);
    return b;
  }
  // Makes room for n elements on device d without keeping the contents: reallocates when the
  // buffer is smaller or lives elsewhere (a default-constructed Buffer is an empty CPU buffer, so
  // the device must be named here).
  void reserve_discard(std::int64_t n, Device d) {
    if (n > size_ || d != device_) *this = Buffer(n, d);
  }

 private:
  void swap(Buffer& o) noexcept {
    std::swap(device_, o.device_);
    std::swap(data_, o.data_);
    std::swap(size_, o.size_);
  }
  Device device_ = Device::CPU;
  T* data_ = nullptr;
  std::int64_t size_ = 0;
};

template <class T> class Image {
 public:
  Image() = default;
  Image(int w, int h, Device d) : buf_(static_cast<std::int64_t>(w) * h, d), w_(w), h_(h) {}
  static Image pinned_host(int w, int h) {
    Image im;
    im.buf_ = Buffer<T>::pinned_host(static_cast<std::int64_t>(w) * h);
    im.w_ = w, im.h_ = h;
    return im;
  }
  static Image from_host(const std::vector<T>& v, int w, int h, Device d) {
    Image im(w, h, d);
    im.buf_.copy_from_host(v.data(), im.buf_.size());
    return im;
  }
  int width() const { return w_; }
  int height() const { return h_; }
  Device device() const { return buf_.device(); }
  View2D<T> view() const { return {buf_.data(), w_, h_, w_}; }
  View2D<const T> cview() const { return {buf_.data(), w_, h_, w_}; }
  Buffer<T>& buffer() { return buf_; }
  const Buffer<T>& buffer() const { return buf_; }
  std::vector<T> to_host() const { return buf_.to_host(); }
  Image clone(Device d) const {
    Image im(w_, h_, d);
    im.buf_.copy_from(buf_);
    return im;
  }

 private:
  Buffer<T> buf_;
  int w_ = 0, h_ = 0;
};

}  // namespace seamless
