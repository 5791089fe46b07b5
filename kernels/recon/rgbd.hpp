// RGB-D tracking: the point-to-plane ICP of icp.hpp plus a photometric term in one Gauss-Newton
// solve (in the spirit of Steinbruecker, Sturm, Cremers 2011 and the combined cost of Whelan et al.
// 2013/2015: E = E_icp + w_rgb E_rgb). The photometric residual of a current pixel x with point p is
//   r_I = I_ref(pi(q)) - I_cur(x),   q = ref_T_cur p,
// and with g = dI_ref/dq = grad I . d pi/dq (chain rule through the pinhole projection) the same
// left-update parametrisation as the ICP gives J_I = [ (q x g)^T, g^T ].
#pragma once
#include "kernels/recon/icp.hpp"

namespace seamless::kernels {

struct RgbdLevel {
  IcpLevel geo;
  View2D<const float> cur_intensity;  // [0, 1], same size as geo.cur_vertex
  View2D<const float> ref_intensity;  // [0, 1], same size as geo.ref_vertex
  float geometric_weight = 1.f;
  float photometric_weight = 0.1f;
  float max_intensity_diff = 0.3f;  // larger photometric residuals are outliers (specularities, occlusions)
};

// Bilinear sample; the caller keeps (x, y) inside [0, w-1) x [0, h-1).
SEAMLESS_HD inline float bilinear(View2D<const float> im, float x, float y) {
  int x0 = static_cast<int>(floorf(x)), y0 = static_cast<int>(floorf(y));
  float ax = x - x0, ay = y - y0;
  float top = (1.f - ax) * im(x0, y0) + ax * im(x0 + 1, y0);
  float bot = (1.f - ax) * im(x0, y0 + 1) + ax * im(x0 + 1, y0 + 1);
  return (1.f - ay) * top + ay * bot;
}

// Adds the photometric row of a geometric correspondence c of current pixel (x, y). Only pixels
// that passed the geometric tests get one: that is the occlusion check (the reference pixel shows
// the same surface), and it keeps the term away from depth edges where intensity means nothing.
SEAMLESS_HD inline void add_photometric(IcpTerms& s, const RgbdLevel& L, const Correspondence& c, int x, int y) {
  const Intrinsics& K = L.geo.K;
  float u = c.uv.x, v = c.uv.y;
  if (u < 1.f || v < 1.f || u >= L.ref_intensity.width - 2.f || v >= L.ref_intensity.height - 2.f) return;
  float r = bilinear(L.ref_intensity, u, v) - L.cur_intensity(x, y);
  if (fabsf(r) > L.max_intensity_diff) return;
  float gx = 0.5f * (bilinear(L.ref_intensity, u + 1.f, v) - bilinear(L.ref_intensity, u - 1.f, v));
  float gy = 0.5f * (bilinear(L.ref_intensity, u, v + 1.f) - bilinear(L.ref_intensity, u, v - 1.f));
  float iz = 1.f / c.q.z;
  vec3 g{gx * K.fx * iz, gy * K.fy * iz, -(gx * K.fx * c.q.x + gy * K.fy * c.q.y) * iz * iz};
  add_row(s, cross(c.q, g), g, r, L.photometric_weight);
}

// Sums the combined geometric + photometric normal equations over the current level (one pass).
// error holds the weighted sum of both terms; inliers counts geometric correspondences.
// (at the estimate *pose, into *out on the device, then `update`, like icp_reduce_into)
template <class Exec>
void rgbd_reduce_into(const Exec& ex, RgbdLevel level, IcpPose* pose, IcpSums* out, IcpUpdate update);

// Intensity in [0, 1] from 8-bit RGB (ITU-R BT.601 luma weights).
template <class Exec>
void rgb_to_intensity(const Exec& ex, View2D<const uchar3> rgb, View2D<float> out);

}  // namespace seamless::kernels
