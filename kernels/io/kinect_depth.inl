// Kernel bodies for io/kinect_depth.hpp, compiled once per backend.
#include <cmath>

#include "core/atomics.hpp"
#include "kernels/io/kinect_depth.hpp"

namespace seamless::kernels {

template <Executor Exec>
void KinectDepth<Exec>::raw_to_metres(const Exec& ex, const KinectDisparityModel& m, View2D<const std::uint16_t> raw,
                                      View2D<float> out) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    out(x, y) = kinect_raw_to_metres(m, raw(x, y));
  });
}

template <Executor Exec>
void KinectDepth<Exec>::register_to_colour(const Exec& ex, const KinectDisparityModel& m,
                                           View2D<const std::uint16_t> raw, View2D<const vec2> table,
                                           View2D<std::uint32_t> zbuf, View2D<float> out) {
  const int w = zbuf.width, rw = raw.width;
  ex.for_each(zbuf.count(), [=] SEAMLESS_HD(std::int64_t i) {
    zbuf(static_cast<int>(i % w), static_cast<int>(i / w)) = kKinectEmptyDepth;
  });
  ex.for_each(raw.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % rw), y = static_cast<int>(i / rw);
    const float z = kinect_raw_to_metres(m, raw(x, y));
    const vec2 t = table(x, y);
    if (z <= 0.f || t.x < 0.f) return;
    const float uf = floorf(t.x + kinect_parallax(m, z));
    if (!(uf >= 0.f && uf < static_cast<float>(zbuf.width) && t.y >= 0.f && t.y < static_cast<float>(zbuf.height)))
      return;
    const int u = static_cast<int>(uf), v = static_cast<int>(t.y);
    // Micrometres: integers order like depths, and atomic_min keeps the nearest surface.
    atomic_min(&zbuf(u, v), static_cast<std::uint32_t>(z * 1e6f + 0.5f));
  });
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    const std::uint32_t d = zbuf(x, y);
    out(x, y) = d == kKinectEmptyDepth ? 0.f : static_cast<float>(d) * 1e-6f;
  });
}

}  // namespace seamless::kernels
