// The CPU's ICP and RGB-D terms on 8 SIMD lanes (defined in icp_simd.cpp, compiled for AVX2 where
// simd::cpu_simd() finds it at run time). Never seen by nvcc.
//
// A Gauss-Newton step sums every pixel's rows (icp_pixel_terms, icp.inl; rgbd_pixel_terms,
// rgbd.inl): on the CPU, one pixel after the other, each a projective lookup, for RGB-D five
// bilinear intensity samples, and a few dozen products. Here lane l takes pixel begin + l of 8
// consecutive pixels: each lane runs find_correspondence's tests, photometric_residual's and
// add_row's products with the scalar expressions (no FMA contraction: core/simd.hpp), and the
// lanes' terms are then added into the running sums pixel by pixel, so the sums are
// transform_reduce's bit for bit (CpuExec::reduce_ranges hands each thread its share whole; tests
// compare both).
#pragma once
#if !defined(__CUDACC__)
#include <cstdint>

#include "core/cpu_simd.hpp"
#include "kernels/recon/icp.hpp"
#include "kernels/recon/rgbd.hpp"

namespace seamless::kernels {

// Whether the CPU sums level L's (R's) terms on the lanes: it has AVX2, and the lanes reach the
// maps' floats with 32-bit indices.
inline bool icp_on_lanes(const IcpLevel& L) {
  auto fits = [](View2D<const vec3> v) { return v.pitch * v.height * 3 < (std::int64_t{1} << 31); };
  return simd::cpu_simd() && fits(L.cur_vertex) && fits(L.cur_normal) && fits(L.ref_vertex) && fits(L.ref_normal);
}
inline bool rgbd_on_lanes(const RgbdLevel& R) {
  auto fits = [](View2D<const float> v) { return v.pitch * (v.height + 1) < (std::int64_t{1} << 31); };
  return icp_on_lanes(R.geo) && fits(R.cur_intensity) && fits(R.ref_intensity);
}

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {
// s += icp_pixel_terms(L, T, i) for i = begin .. end - 1 in order (T: the estimate as floats,
// to_se3 of the pose).
void add_icp_terms_simd(const IcpLevel& L, const SE3& T, std::int64_t begin, std::int64_t end, IcpSums& s);
// s += rgbd_pixel_terms(R, p, i) for i = begin .. end - 1 in order.
void add_rgbd_terms_simd(const RgbdLevel& R, const IcpPose& p, std::int64_t begin, std::int64_t end, RgbdSums& s);
}  // namespace detail
SEAMLESS_SIMD_TARGET_END

// The add of CpuExec::reduce_ranges that sums level L's (R's) terms at *pose on the lanes.
inline auto icp_lanes(const IcpLevel& L, const IcpPose* pose) {
  return [=](std::int64_t begin, std::int64_t end, IcpSums& s) {
    detail::add_icp_terms_simd(L, to_se3(*pose), begin, end, s);
  };
}
inline auto rgbd_lanes(const RgbdLevel& R, const IcpPose* pose) {
  return
      [=](std::int64_t begin, std::int64_t end, RgbdSums& s) { detail::add_rgbd_terms_simd(R, *pose, begin, end, s); };
}

}  // namespace seamless::kernels
#endif
