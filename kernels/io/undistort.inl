// Kernel bodies for io/undistort.hpp, compiled once per backend.
#include <cmath>

#include "kernels/io/undistort.hpp"

namespace seamless::kernels {

template <Executor Exec> void Undistort<Exec>::undistort_map(const Exec& ex, Intrinsics K, View2D<vec2> map) {
  const int w = map.width;
  ex.for_each(map.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    map(x, y) = distort_pixel(K, static_cast<float>(x), static_cast<float>(y));
  });
}

template <Executor Exec>
void Undistort<Exec>::remap_depth(const Exec& ex, View2D<const vec2> map, View2D<const float> in, View2D<float> out) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec2 s = map(x, y);
    int sx = floor_int(s.x + 0.5f), sy = floor_int(s.y + 0.5f);
    out(x, y) = in.inside(sx, sy) ? in(sx, sy) : 0.f;
  });
}

template <Executor Exec>
void Undistort<Exec>::remap_rgb(const Exec& ex, View2D<const vec2> map, View2D<const uchar3> in, View2D<uchar3> out) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec2 s = map(x, y);
    if (!colour_lookup_inside(s, in.width, in.height)) {
      out(x, y) = {0, 0, 0};
      return;
    }
    int x0 = floor_int(s.x), y0 = floor_int(s.y);
    float ax = s.x - x0, ay = s.y - y0;
    uchar3 a = in(x0, y0), b = in(x0 + 1, y0), c = in(x0, y0 + 1), d = in(x0 + 1, y0 + 1);
    auto mix = [=](float va, float vb, float vc, float vd) {
      float v = (1 - ay) * ((1 - ax) * va + ax * vb) + ay * ((1 - ax) * vc + ax * vd);
      return static_cast<std::uint8_t>(min_of(v + 0.5f, 255.f));
    };
    out(x, y) = {mix(a.x, b.x, c.x, d.x), mix(a.y, b.y, c.y, d.y), mix(a.z, b.z, c.z, d.z)};
  });
}

}  // namespace seamless::kernels
