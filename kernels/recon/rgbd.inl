// Kernel bodies for recon/rgbd.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/rgbd.hpp"
#if !defined(__CUDACC__)
#include "kernels/recon/icp_simd.hpp"
#endif

namespace seamless::kernels {

// One pixel's geometric and photometric terms at the estimate p (R.geo.ref_T_cur is ignored).
SEAMLESS_HD inline RgbdTerms rgbd_pixel_terms(const RgbdLevel& R, const IcpPose& p, std::int64_t i) {
  RgbdTerms s{};
  RgbdLevel L = R;
  L.geo.ref_T_cur = to_se3(p);
  int x, y;
  level_pixel(L.geo, i, x, y);
  if (valid_point(L.geo.cur_vertex(x, y))) s.icp.valid = 1.f;
  Correspondence c;
  bool geometric;
  if (find_rgbd_correspondence(L, x, y, c, geometric)) add_rgbd_rows(s, L, c, x, y, p.geo_var, p.photo_var, geometric);
  return s;
}

// What a reduction does with its summed system: keeps it as the level's, applies `update` (with
// the variances this system was built with), then re-estimates the variances (robust weighting).
SEAMLESS_HD inline void rgbd_update(const RgbdLevel& R, const RgbdSums& out, IcpPose& pose, IcpSums& level_sums,
                                    IcpUpdate update) {
  level_sums = out.icp;
  gauss_newton_update(out.icp, pose, update, R.geo);
  if (R.dof > 0.f) update_scale(out, pose);
}

// On the CPU with AVX2 the pixels' terms are summed 8 at a time on SIMD lanes (icp_simd.hpp: the
// same sums as transform_reduce's, bit for bit).
template <Executor Exec>
void Rgbd<Exec>::rgbd_reduce_into(const Exec& ex, RgbdLevel R, IcpPose* pose, RgbdSums* out, IcpSums* level_sums) {
  auto then = [=] SEAMLESS_HD { rgbd_update(R, *out, *pose, *level_sums, IcpUpdate::none); };
#if !defined(__CUDACC__)
  if constexpr (Exec::device == Device::CPU)
    if (rgbd_on_lanes(R)) {
      *out = ex.reduce_ranges(level_pixel_count(R.geo), RgbdSums{}, rgbd_lanes(R, pose));
      return then();
    }
#endif
  ex.transform_reduce_into(
      level_pixel_count(R.geo), [=] SEAMLESS_HD(std::int64_t i) { return rgbd_pixel_terms(R, *pose, i); }, out, then);
}

template <Executor Exec>
void Rgbd<Exec>::rgbd_level_steps(const Exec& ex, RgbdLevel R, IcpPose* pose, RgbdSums* out, IcpSums* level_sums,
                                  int steps) {
  auto then = [=] SEAMLESS_HD(int step, const RgbdSums& sum) {
    rgbd_update(R, sum, *pose, *level_sums, level_step(step));
    return level_done(*pose);
  };
#if !defined(__CUDACC__)
  if constexpr (Exec::device == Device::CPU)
    if (rgbd_on_lanes(R))
      return ex.reduce_ranges_rounds(level_pixel_count(R.geo), steps, rgbd_lanes(R, pose), out, then);
#endif
  ex.transform_reduce_rounds(
      level_pixel_count(R.geo), steps, [=] SEAMLESS_HD(std::int64_t i) { return rgbd_pixel_terms(R, *pose, i); }, out,
      then);
}

template <Executor Exec>
void Rgbd<Exec>::rgb_to_intensity(const Exec& ex, View2D<const uchar3> rgb, View2D<float> out) {
  const int w = rgb.width;
  ex.for_each(rgb.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    uchar3 c = rgb(x, y);
    const bool none = c.x == 0 && c.y == 0 && c.z == 0;
    out(x, y) = none ? kNoIntensity : (0.299f * c.x + 0.587f * c.y + 0.114f * c.z) * (1.f / 255.f);
  });
}

}  // namespace seamless::kernels
