// RGB-D tracking: the point-to-plane ICP of icp.hpp plus a photometric term in one Gauss-Newton
// solve (in the spirit of Steinbruecker, Sturm, Cremers 2011 and the combined cost of Whelan et al.
// 2013/2015: E = E_icp + w_rgb E_rgb). The photometric residual of a current pixel x with point p is
//   r_I = I_ref(pi(q)) - I_cur(x),   q = ref_T_cur p,
// and with g = dI_ref/dq = grad I . d pi/dq (chain rule through the pinhole projection) the same
// left-update parametrisation as the ICP gives J_I = [ (q x g)^T, g^T ].
#pragma once
#include "core/exec.hpp"
#include "kernels/recon/icp.hpp"

namespace seamless::kernels {

struct RgbdLevel {
  IcpLevel geo;
  View2D<const float> cur_intensity;  // [0, 1], same size as geo.cur_vertex
  View2D<const float> ref_intensity;  // [0, 1], same size as geo.ref_vertex
  float geometric_weight = 1.f;
  float photometric_weight = 0.1f;
  float max_intensity_diff = 0.3f;  // larger photometric residuals are outliers (specularities, occlusions)
  // > 0: robust, self-balancing weights (tracker.weighting: robust) with a Student t-distribution of
  // this many degrees of freedom; 0: the fixed weights above (tracker.weighting: fixed).
  float dof = 0.f;
  // Robust weighting only: the geometric residual's standard deviation grows with depth squared
  // (structured light, Kinect v1: Khoshelham & Elberink 2012, sigma_z ~ z^2), so each geometric
  // residual is divided by (z / 1 m)^2 before the scale and the t-weight see it (in metres "at 1 m").
  bool depth_squared_noise = false;
  // Which pixels get a photometric row. false: only the geometric inliers (the 20-degree normal test
  // included). true: every pixel whose projection finds a reference vertex within dist_threshold
  // (visible, not occluded), whatever its normals: the normal test guards the point-to-plane row
  // against noisy normals, but the colour residual does not use normals, and on far Kinect depth
  // (normals from ~1 cm noise) the normal test leaves only a quarter of the pixels (docs/TRACKING.md).
  bool photometric_all_visible = false;
  // Photometric rows only where the reference intensity gradient (central difference, intensity
  // [0, 1] per pixel) is at least this large: flat pixels carry no information about the motion
  // but their noise still enters the photometric scale (OpenCV RgbdOdometry's minGradientMagnitudes).
  float min_gradient = 0.f;
};

// ---- Robust, self-balancing weighting (tracker.weighting: robust) --------------------------------
// Each residual type k (geometric r_g in metres, photometric r_I in intensity units) is modelled as
// Student-t distributed with its own scale sigma_k^2 (Kerl, Sturm, Cremers, "Robust Odometry
// Estimation for RGB-D Cameras", ICRA 2013, sec. III-C/IV: the t-distribution's iteratively
// reweighted least squares; their combined geometric + photometric version, "Dense Visual SLAM for
// RGB-D Cameras", IROS 2013, sec. III, uses a bivariate t with a 2x2 scale matrix; here its diagonal,
// so a pixel without a photometric row still has a geometric one). Per residual, the IRLS weight is
//   w(r) = (nu + 1) / (nu + r^2 / sigma^2),
// and the scale is the fixed point of
//   sigma^2 = 1/n sum_i w(r_i) r_i^2,
// which we iterate once per Gauss-Newton step: the sums of w r^2 and the counts of both types are
// reduced with the normal equations (three more scalars; no per-pixel sort), and the step's
// last thread turns them into the next step's sigma_g^2, sigma_I^2 (IcpPose::geo_var / photo_var).
// Each row is then whitened, weight w / sigma_k^2, which balances the two types by their own noise
// instead of a fixed photometric_weight (a hundredfold imbalance on Kinect data: intensity
// gradients of ~10 per metre against unit normals). The whole system is multiplied by sigma_g^2 so
// that J^T J and the error stay in metres (the solution does not change): the geometric row gets
// w_g, the photometric row photometric_weight * w_I * sigma_g^2 / sigma_I^2 (photometric_weight 1 =
// equal trust in one whitened residual of each type). Until a scale is known (a frame's first,
// scale-only reduction) the t-weights are 1, so the first estimate is the plain RMS.
template <class S> struct RgbdSumsOf {
  IcpSumsOf<S> icp;  // the combined weighted system, as the ICP's
  S geo_wr2;         // sum over geometric rows of w_g r_g^2 (robust weighting only)
  S photo_wr2;       // sum over photometric rows of w_I r_I^2 (robust weighting only)
  S photo_n;         // photometric rows
};
using RgbdSums = RgbdSumsOf<double>;
using RgbdTerms = RgbdSumsOf<float>;

template <class A, class B> SEAMLESS_HD inline RgbdSumsOf<A> operator+(const RgbdSumsOf<A>& a, const RgbdSumsOf<B>& b) {
  RgbdSumsOf<A> s;
  s.icp = a.icp + b.icp;
  s.geo_wr2 = a.geo_wr2 + b.geo_wr2;
  s.photo_wr2 = a.photo_wr2 + b.photo_wr2;
  s.photo_n = a.photo_n + b.photo_n;
  return s;
}

// Smallest variances the scale estimate may reach, so that residuals of exactly zero (noise-free
// synthetic data) cannot make a weight infinite: the photometric one is the variance of 8-bit
// quantisation, (1/255)^2 / 12; the geometric one (10 micrometres)^2, far below any depth sensor's
// resolution (Kinect v1: ~1 mm at 1 m), so it never binds on real data.
constexpr float kMinPhotoVar = 1.f / (255.f * 255.f * 12.f);
constexpr float kMinGeoVar = 1e-10f;

// t-distribution IRLS weight of residual r at variance var (1 while var is unknown, i.e. 0).
SEAMLESS_HD inline float t_weight(float r, float var, float dof) {
  return var > 0.f ? (dof + 1.f) / (dof + r * r / var) : 1.f;
}

// The next step's variances from this step's sums (the fixed point above); unchanged when a type
// had no residual.
SEAMLESS_HD inline void update_scale(const RgbdSums& s, IcpPose& p) {
  if (s.icp.inliers > 0) p.geo_var = fmaxf(static_cast<float>(s.geo_wr2 / s.icp.inliers), kMinGeoVar);
  if (s.photo_n > 0) p.photo_var = fmaxf(static_cast<float>(s.photo_wr2 / s.photo_n), kMinPhotoVar);
}

// An intensity pixel without a colour reading. RGB (0, 0, 0) means no reading, as depth 0 does:
// the undistortion of freiburg1/2 images (kernels/io/undistort.hpp) writes it where the lens saw
// nothing, a 6-25 pixel border. Used as colour, that border is a sharp black edge fixed in the
// image: every photometric row that samples it pulls the estimate towards no motion (the 4-5 %
// too small yaw of frame-to-model tracking on fr1_rpy, docs/HISTORY.md, "Session 5", the rotation slope).
constexpr float kNoIntensity = -1.f;

// Bilinear sample into v; false when one of the four pixels has no reading (kNoIntensity). The
// caller keeps (x, y) inside [0, w-1) x [0, h-1).
SEAMLESS_HD inline bool bilinear(View2D<const float> im, float x, float y, float& v) {
  int x0 = floor_int(x), y0 = floor_int(y);
  float ax = x - x0, ay = y - y0;
  const float a = im(x0, y0), b = im(x0 + 1, y0), c = im(x0, y0 + 1), d = im(x0 + 1, y0 + 1);
  v = (1.f - ay) * ((1.f - ax) * a + ax * b) + ay * ((1.f - ax) * c + ax * d);
  // Comparisons, not fminf: intensities are never NaN, and on the CPU each fminf is a libm call
  // (GCC keeps its NaN rule out of line), 15 of them a pixel in photometric_residual.
  return a >= 0.f && b >= 0.f && c >= 0.f && d >= 0.f;
}

// The photometric residual r and its gradient g = dI_ref/dq of a geometric correspondence c of
// current pixel (x, y); false when it has none (near the border, a sample without a colour reading,
// or |r| > max_intensity_diff). Only pixels that passed the geometric tests get one: that is the
// occlusion check (the reference pixel shows the same surface), and it keeps the term away from
// depth edges where intensity means nothing.
SEAMLESS_HD inline bool photometric_residual(const RgbdLevel& L, const Correspondence& c, int x, int y, float& r,
                                             vec3& g) {
  const Intrinsics& K = L.geo.K;
  float u = c.uv.x, v = c.uv.y;
  if (u < 1.f || v < 1.f || u >= L.ref_intensity.width - 2.f || v >= L.ref_intensity.height - 2.f) return false;
  const float cur = L.cur_intensity(x, y);
  float ref, xp, xm, yp, ym;
  if (!(cur >= 0.f) || !bilinear(L.ref_intensity, u, v, ref)) return false;
  r = ref - cur;
  if (fabsf(r) > L.max_intensity_diff) return false;
  if (!bilinear(L.ref_intensity, u + 1.f, v, xp) || !bilinear(L.ref_intensity, u - 1.f, v, xm) ||
      !bilinear(L.ref_intensity, u, v + 1.f, yp) || !bilinear(L.ref_intensity, u, v - 1.f, ym))
    return false;
  float gx = 0.5f * (xp - xm);
  float gy = 0.5f * (yp - ym);
  if (gx * gx + gy * gy < L.min_gradient * L.min_gradient) return false;
  float iz = 1.f / c.q.z;
  g = vec3{gx * K.fx * iz, gy * K.fy * iz, -(gx * K.fx * c.q.x + gy * K.fy * c.q.y) * iz * iz};
  return true;
}

// The point-to-plane row of correspondence c, with the fixed weight (L.dof == 0) or the robust one at
// the previous step's variance (see above).
SEAMLESS_HD inline void add_geometric_row(RgbdTerms& s, const RgbdLevel& L, const Correspondence& c, float geo_var) {
  const float rg = dot(c.n, c.q - c.v);
  float wg = L.geometric_weight;
  if (L.dof > 0.f) {
    // residual rn = rg / z^2 with depth_squared_noise: its row is the original one weighted by 1/z^4
    const float iz2 = L.depth_squared_noise ? 1.f / (c.q.z * c.q.z) : 1.f;
    const float rn = rg * iz2;
    wg = t_weight(rn, geo_var, L.dof);
    s.geo_wr2 += wg * rn * rn;
    wg *= iz2 * iz2;
  }
  add_row(s.icp, cross(c.q, c.n), c.n, rg, wg);
  s.icp.inliers += 1.f;
}

// The rows of current pixel (x, y) and its projective correspondence c: the geometric one when c
// passed every geometric test (`geometric`), the photometric one when the pixel has one; weights as
// above, at the previous step's variances.
SEAMLESS_HD inline void add_rgbd_rows(RgbdTerms& s, const RgbdLevel& L, const Correspondence& c, int x, int y,
                                      float geo_var, float photo_var, bool geometric = true) {
  if (geometric) add_geometric_row(s, L, c, geo_var);
  float r;
  vec3 g;
  if (!photometric_residual(L, c, x, y, r, g)) return;
  float wi = L.photometric_weight;
  if (L.dof > 0.f) {
    const float t = t_weight(r, photo_var, L.dof);
    s.photo_wr2 += t * r * r;
    s.photo_n += 1.f;
    wi *= t * (geo_var > 0.f && photo_var > 0.f ? geo_var / photo_var : 1.f);
  }
  add_row(s.icp, cross(c.q, g), g, r, wi);
}

// The correspondence of current pixel (x, y) for both rows: false when it has none for either; with
// L.photometric_all_visible the normal test decides only `geometric` (see RgbdLevel), otherwise a
// correspondence is a geometric inlier or nothing.
SEAMLESS_HD inline bool find_rgbd_correspondence(const RgbdLevel& L, int x, int y, Correspondence& c, bool& geometric) {
  geometric = true;
  if (!L.photometric_all_visible) return find_correspondence(L.geo, x, y, c);
  IcpLevel visible = L.geo;
  visible.cos_angle = -2.f;  // every normal angle passes: the visibility tests only
  if (!find_correspondence(visible, x, y, c)) return false;
  geometric = dot(L.geo.ref_T_cur.rotate(L.geo.cur_normal(x, y)), c.n) >= L.geo.cos_angle;
  return true;
}

template <Executor Exec> struct Rgbd {
  // Sums the combined geometric + photometric normal equations over the current level (one pass) at
  // the estimate *pose into *out on the device; then, in the same launch, copies the system into
  // *level_sums (where the tracker reads each level's last system) and, with robust weighting,
  // re-estimates the variances in *pose. error holds the weighted sum of both terms; inliers counts
  // geometric correspondences.
  static void rgbd_reduce_into(const Exec& ex, RgbdLevel level, IcpPose* pose, RgbdSums* out, IcpSums* level_sums);

  // Up to `steps` Gauss-Newton steps of one level in one device launch, like icp_level_steps: each
  // sums at *pose, keeps the system in *level_sums, steps, and re-estimates the variances.
  static void rgbd_level_steps(const Exec& ex, RgbdLevel level, IcpPose* pose, RgbdSums* out, IcpSums* level_sums,
                               int steps);

  // Intensity in [0, 1] from 8-bit RGB (ITU-R BT.601 luma weights); kNoIntensity where RGB is
  // (0, 0, 0), no colour reading (see kNoIntensity).
  static void rgb_to_intensity(const Exec& ex, View2D<const uchar3> rgb, View2D<float> out);
};

}  // namespace seamless::kernels
