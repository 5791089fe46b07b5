// Views are what kernels see: a pointer and a size, no ownership. They are trivially copyable so a
// lambda can capture them by value on either backend.
#pragma once
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "core/hd.hpp"

namespace seamless {

template <class T> struct View {
  T* data = nullptr;
  std::int64_t size = 0;
  SEAMLESS_HD T& operator[](std::int64_t i) const { return data[i]; }
  template <class U = T>
  requires(!std::is_const_v<U>) SEAMLESS_HD operator View<const U>() const { return {data, size}; }
};

// A pitched 2-D image; pitch is in elements (>= width).
template <class T> struct View2D {
  T* data = nullptr;
  int width = 0, height = 0;
  std::int64_t pitch = 0;
  SEAMLESS_HD T& operator()(int x, int y) const { return data[static_cast<std::int64_t>(y) * pitch + x]; }
  SEAMLESS_HD bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  SEAMLESS_HD std::int64_t count() const { return static_cast<std::int64_t>(width) * height; }
  template <class U = T>
  requires(!std::is_const_v<U>) SEAMLESS_HD operator View2D<const U>() const { return {data, width, height, pitch}; }
};

}  // namespace seamless
