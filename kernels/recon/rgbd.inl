// Kernel bodies for recon/rgbd.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/rgbd.hpp"

namespace seamless::kernels {

template <class Exec>
IcpSums rgbd_reduce(const Exec& ex, RgbdLevel L) {
  const int w = L.geo.cur_vertex.width;
  return ex.transform_reduce(L.geo.cur_vertex.count(), IcpSums{}, [=] SEAMLESS_HD(std::int64_t i) {
    IcpSums s{};
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (valid_point(L.geo.cur_vertex(x, y))) s.valid = 1.0;
    Correspondence c;
    if (find_correspondence(L.geo, x, y, c)) {
      add_point_to_plane(s, c, L.geometric_weight);
      add_photometric(s, L, c, x, y);
    }
    return s;
  });
}

template <class Exec>
void rgb_to_intensity(const Exec& ex, View2D<const uchar3> rgb, View2D<float> out) {
  const int w = rgb.width;
  ex.for_each(rgb.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    uchar3 c = rgb(x, y);
    out(x, y) = (0.299f * c.x + 0.587f * c.y + 0.114f * c.z) * (1.f / 255.f);
  });
}

}  // namespace seamless::kernels

#define SEAMLESS_INSTANTIATE_RGBD(EXEC)                                                   \
  namespace seamless::kernels {                                                           \
  template IcpSums rgbd_reduce<EXEC>(const EXEC&, RgbdLevel);                             \
  template void rgb_to_intensity<EXEC>(const EXEC&, View2D<const uchar3>, View2D<float>); \
  }
