// Kernel bodies for recon/icp.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/icp.hpp"
#if !defined(__CUDACC__)
#include "kernels/recon/icp_simd.hpp"
#endif

namespace seamless::kernels {

// One pixel's point-to-plane terms at the estimate p (level.ref_T_cur is ignored).
SEAMLESS_HD inline IcpTerms icp_pixel_terms(const IcpLevel& level, const IcpPose& p, std::int64_t i) {
  IcpTerms s{};
  IcpLevel l = level;
  l.ref_T_cur = to_se3(p);
  int x, y;
  level_pixel(l, i, x, y);
  if (valid_point(l.cur_vertex(x, y))) s.valid = 1.f;
  Correspondence c;
  if (find_correspondence(l, x, y, c)) add_point_to_plane(s, c, 1.f);
  return s;
}

// On the CPU with AVX2 the pixels' terms are summed 8 at a time on SIMD lanes (icp_simd.hpp: the
// same sums as transform_reduce's, bit for bit).
template <Executor Exec> void Icp<Exec>::icp_reduce_into(const Exec& ex, IcpLevel L, IcpPose* pose, IcpSums* out) {
#if !defined(__CUDACC__)
  if constexpr (Exec::device == Device::CPU)
    if (icp_on_lanes(L)) {
      *out = ex.reduce_ranges(level_pixel_count(L), IcpSums{}, icp_lanes(L, pose));
      return;
    }
#endif
  ex.transform_reduce_into(
      level_pixel_count(L), [=] SEAMLESS_HD(std::int64_t i) { return icp_pixel_terms(L, *pose, i); }, out);
}

template <Executor Exec>
void Icp<Exec>::icp_level_steps(const Exec& ex, IcpLevel L, IcpPose* pose, IcpSums* out, int steps) {
  auto then = [=] SEAMLESS_HD(int step, const IcpSums& sum) {
    gauss_newton_update(sum, *pose, level_step(step), L);
    return level_done(*pose);
  };
#if !defined(__CUDACC__)
  if constexpr (Exec::device == Device::CPU)
    if (icp_on_lanes(L)) return ex.reduce_ranges_rounds(level_pixel_count(L), steps, icp_lanes(L, pose), out, then);
#endif
  ex.transform_reduce_rounds(
      level_pixel_count(L), steps, [=] SEAMLESS_HD(std::int64_t i) { return icp_pixel_terms(L, *pose, i); }, out, then);
}

template <Executor Exec>
void Icp<Exec>::transform_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, SE3 T, View2D<vec3> vout,
                               View2D<vec3> nout) {
  const int w = vin.width;
  ex.for_each(vin.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec3 v = vin(x, y), n = nin(x, y);
    bool ok = length2(v) > 0.f && valid_normal(n);
    vec3 tv = ok ? T * v : vec3{0.f, 0.f, 0.f};
    // A point behind the reference camera cannot be seen from it: drop it.
    if (tv.z <= 0.f) ok = false;
    vout(x, y) = ok ? tv : vec3{0.f, 0.f, 0.f};
    nout(x, y) = ok ? T.rotate(n) : vec3{0.f, 0.f, 0.f};
  });
}

template <Executor Exec>
void Icp<Exec>::pyr_down_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, View2D<vec3> vout,
                              View2D<vec3> nout, float max_diff) {
  const int w = vout.width;
  ex.for_each(vout.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec3 vs{0.f, 0.f, 0.f}, ns{0.f, 0.f, 0.f};
    float ref = 0.f;
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      int xx = 2 * x + (k & 1), yy = 2 * y + (k >> 1);
      if (!vin.inside(xx, yy)) continue;
      vec3 v = vin(xx, yy), nn = nin(xx, yy);
      if (!valid_point(v) || !valid_normal(nn)) continue;
      if (n == 0) ref = v.z;
      if (fabsf(v.z - ref) <= max_diff) {
        vs += v;
        ns += nn;
        ++n;
      }
    }
    vec3 nm = n ? normalize(ns) : vec3{0.f, 0.f, 0.f};
    bool ok = n > 0 && valid_normal(nm);
    vout(x, y) = ok ? vs / static_cast<float>(n) : vec3{0.f, 0.f, 0.f};
    nout(x, y) = ok ? nm : vec3{0.f, 0.f, 0.f};
  });
}

}  // namespace seamless::kernels
