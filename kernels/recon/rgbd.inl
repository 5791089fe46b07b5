// Kernel bodies for recon/rgbd.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/rgbd.hpp"

namespace seamless::kernels {

template <class Exec>
void rgbd_reduce_into(const Exec& ex, RgbdLevel R, IcpPose* pose, RgbdSums* out, IcpSums* level_sums,
                      IcpSums* done, IcpUpdate update) {
  const int w = R.geo.cur_vertex.width;
  ex.transform_reduce_into(R.geo.cur_vertex.count(), [=] SEAMLESS_HD(std::int64_t i) {
    RgbdTerms s{};
    const IcpPose p = *pose;  // the flags with the estimate: one round trip to memory, not two
    if (level_done(p, update)) return s;
    RgbdLevel L = R;
    L.geo.ref_T_cur = to_se3(p);
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    if (valid_point(L.geo.cur_vertex(x, y))) s.icp.valid = 1.f;
    Correspondence c;
    bool geometric;
    if (find_rgbd_correspondence(L, x, y, c, geometric))
      add_rgbd_rows(s, L, c, x, y, p.geo_var, p.photo_var, geometric);
    return s;
  }, out, [=] SEAMLESS_HD {
    if (level_done(*pose, update)) return;
    *level_sums = out->icp;
    // with the variances this system was built with
    if (gauss_newton_update(out->icp, *pose, update, R.geo)) *done = out->icp;
    if (R.dof > 0.f) update_scale(*out, *pose);
  });
}

template <class Exec>
void rgb_to_intensity(const Exec& ex, View2D<const uchar3> rgb, View2D<float> out) {
  const int w = rgb.width;
  ex.for_each(rgb.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    uchar3 c = rgb(x, y);
    const bool none = c.x == 0 && c.y == 0 && c.z == 0;
    out(x, y) = none ? kNoIntensity : (0.299f * c.x + 0.587f * c.y + 0.114f * c.z) * (1.f / 255.f);
  });
}

}  // namespace seamless::kernels

#define SEAMLESS_INSTANTIATE_RGBD(EXEC)                                                   \
  namespace seamless::kernels {                                                           \
  template void rgbd_reduce_into<EXEC>(const EXEC&, RgbdLevel, IcpPose*, RgbdSums*, IcpSums*, IcpSums*, IcpUpdate); \
  template void rgb_to_intensity<EXEC>(const EXEC&, View2D<const uchar3>, View2D<float>); \
  }
