// Point-to-plane ICP after KinectFusion (Newcombe et al. 2011, section 3.5): projective data
// association, rejection by distance and normal angle, and the 6x6 normal equations of one
// Gauss-Newton step summed over all pixels in a single device reduction, then solved (6x6 Cholesky)
// and applied to the estimate by a one-thread kernel, so that a frame's whole coarse-to-fine loop
// runs on the device without a host round trip (the host reads the result once, at the end).
//
// Parametrisation (the "small-angle" linearisation of KinectFusion eq. 16-19): the current estimate
// ref_T_cur is updated on the left, ref_T_cur <- exp(xi) ref_T_cur with xi = (omega, upsilon), so a
// point q = ref_T_cur p moves to q + omega x q + upsilon. The point-to-plane residual of a pair
// (q, reference vertex v, reference normal n) is r = n . (q - v), and its Jacobian is
// J = [ (q x n)^T, n^T ]  (d/d omega of n . (omega x q) = omega . (q x n)).
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// One Gauss-Newton system: upper triangle of J^T W J (row-major, 21 entries), J^T W r (6), the sum of
// weighted squared residuals, and counts. Default-constructed to zero (value-initialised by the
// reduce). A pixel's terms are floats (IcpTerms: half the GPU registers, so twice the threads in
// flight); the sums over a level are doubles (IcpSums): 300k pixels of float products summed in
// float lose digits the 6x6 solve needs. The reductions add terms into sums (operator+ below).
template <class S> struct IcpSumsOf {
  S jtj[21];
  S jtr[6];
  S error;    // sum w r^2
  S inliers;  // geometric correspondences accepted
  S valid;    // current pixels with a vertex (the denominator of the inlier ratio)
};
using IcpSums = IcpSumsOf<double>;
using IcpTerms = IcpSumsOf<float>;

template <class A, class B> SEAMLESS_HD inline IcpSumsOf<A> operator+(const IcpSumsOf<A>& a, const IcpSumsOf<B>& b) {
  // Fully unrolled here and in add_row: constant indices keep the sums in registers (a run-time
  // index would put them in local memory, several times slower on the GPU).
  IcpSumsOf<A> s;
#pragma unroll
  for (int k = 0; k < 21; ++k) s.jtj[k] = a.jtj[k] + b.jtj[k];
#pragma unroll
  for (int k = 0; k < 6; ++k) s.jtr[k] = a.jtr[k] + b.jtr[k];
  s.error = a.error + b.error;
  s.inliers = a.inliers + b.inliers;
  s.valid = a.valid + b.valid;
  return s;
}

// Adds one residual row r with Jacobian J = [a^T, b^T] (6 entries) and weight w.
template <class S> SEAMLESS_HD inline void add_row(IcpSumsOf<S>& s, vec3 a, vec3 b, float r, float w) {
  const float J[6] = {a.x, a.y, a.z, b.x, b.y, b.z};
#pragma unroll
  for (int i = 0; i < 6; ++i) {
    const S wi = static_cast<S>(w) * J[i];
#pragma unroll
    for (int j = i; j < 6; ++j) s.jtj[i * 6 - i * (i - 1) / 2 + (j - i)] += wi * J[j];  // row i of the upper triangle
    s.jtr[i] += wi * r;
  }
  s.error += static_cast<S>(w) * r * r;
}

SEAMLESS_HD inline bool valid_point(vec3 v) { return v.z > 0.f; }
SEAMLESS_HD inline bool valid_normal(vec3 n) { return n.x != 0.f || n.y != 0.f || n.z != 0.f; }

// Everything one pyramid level's reduction needs. Both images are in camera coordinates: the
// current frame's of its own camera, the reference's of the view it was seen or raycast from.
struct IcpLevel {
  View2D<const vec3> cur_vertex, cur_normal;
  View2D<const vec3> ref_vertex, ref_normal;
  Intrinsics K;          // of the reference image at this level
  SE3 ref_T_cur;         // current estimate
  float dist_threshold;  // metres
  float cos_angle;       // cos of the largest normal angle accepted
  // A level stops iterating once a step rotates by less than this (radians) and translates by less
  // than stop_translation (metres); 0 and 0: it always takes all its steps (docs/TRACKING.md).
  float stop_rotation = 0.f;
  float stop_translation = 0.f;
  // The reduction visits every stride-th pixel of every stride-th row (tracker.pixel_stride): a
  // subsample at full resolution, which keeps the finest level's sharp intensity gradients and
  // exact depths (unlike the next, averaged level) at 1/stride^2 of the cost. 1: every pixel.
  int stride = 1;
  // Points farther than this (camera z, metres) on either side have no correspondence
  // (tracker.max_depth); 0: no cut.
  float max_depth = 0.f;
};

// The number of pixels a level's reduction visits, and the i-th of them (row by row).
SEAMLESS_HD inline std::int64_t level_pixel_count(const IcpLevel& L) {
  const int s = L.stride;
  return static_cast<std::int64_t>((L.cur_vertex.width + s - 1) / s) * ((L.cur_vertex.height + s - 1) / s);
}
SEAMLESS_HD inline void level_pixel(const IcpLevel& L, std::int64_t i, int& x, int& y) {
  const int s = L.stride, ws = (L.cur_vertex.width + s - 1) / s;
  x = s * static_cast<int>(i % ws);
  y = s * static_cast<int>(i / ws);
}

// A projective correspondence (KinectFusion eq. 17): the current point moved into the reference
// frame, the reference pixel it projects to, and the reference vertex and normal there.
struct Correspondence {
  vec3 q;     // current point in reference coordinates
  vec2 uv;    // its projection into the reference image (continuous pixel coordinates)
  vec3 v, n;  // reference vertex and normal at the nearest pixel
};

// Finds the correspondence of current pixel (x, y); false when it has none or it is rejected
// (no vertex, behind the camera, outside the image, too far apart, normals too different).
SEAMLESS_HD inline bool find_correspondence(const IcpLevel& L, int x, int y, Correspondence& c) {
  vec3 p = L.cur_vertex(x, y);
  vec3 np = L.cur_normal(x, y);
  if (!valid_point(p) || !valid_normal(np)) return false;
  if (L.max_depth > 0.f && p.z > L.max_depth) return false;
  c.q = L.ref_T_cur * p;
  if (c.q.z <= 0.f) return false;
  c.uv = L.K.project(c.q);
  int u = floor_int(c.uv.x + 0.5f), v = floor_int(c.uv.y + 0.5f);
  if (!L.ref_vertex.inside(u, v)) return false;
  c.v = L.ref_vertex(u, v);
  c.n = L.ref_normal(u, v);
  if (!valid_point(c.v) || !valid_normal(c.n)) return false;
  if (L.max_depth > 0.f && c.v.z > L.max_depth) return false;
  if (length2(c.q - c.v) > L.dist_threshold * L.dist_threshold) return false;
  return dot(L.ref_T_cur.rotate(np), c.n) >= L.cos_angle;
}

// The point-to-plane row of a correspondence (see the header comment).
SEAMLESS_HD inline void add_point_to_plane(IcpTerms& s, const Correspondence& c, float w) {
  add_row(s, cross(c.q, c.n), c.n, dot(c.n, c.q - c.v), w);
  s.inliers += 1.f;
}

// The estimate ref_T_cur of one Gauss-Newton loop, kept on the device in double: ~20 left
// compositions of float rotations would drift from orthonormal.
struct IcpPose {
  double R[9];  // row-major
  double t[3];
  int stalled;    // the solve failed at this level: the level's later steps change nothing
  int steps;      // Gauss-Newton steps taken; a stalled level counts its failing step
  int converged;  // this level's last step was below the stop thresholds: its later steps are skipped
  // RGB-D robust weighting only (kernels/recon/rgbd.hpp, RgbdScale): the geometric (m^2) and
  // photometric residual variances estimated by the previous step; 0 = not estimated yet. Kept next
  // to the estimate so that one host copy starts a frame; the ICP kernel never reads them.
  float geo_var;
  float photo_var;
};

// What a frame's Gauss-Newton loop keeps on the device, in one allocation so that the host reads
// the result with one copy: the estimate and the last system summed at each pyramid level (a
// level's steps end once it is done, so that is the system of its converging or stalling step).
constexpr int kIcpMaxLevels = 8;
struct IcpState {
  IcpPose pose;
  IcpSums sums[kIcpMaxLevels];
};

SEAMLESS_HD inline IcpPose to_icp_pose(const SE3& T) {
  IcpPose p{};
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) p.R[3 * r + c] = T.R.m[r][c];
  p.t[0] = T.t.x, p.t[1] = T.t.y, p.t[2] = T.t.z;
  return p;
}
SEAMLESS_HD inline SE3 to_se3(const IcpPose& p) {
  SE3 T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R.m[r][c] = static_cast<float>(p.R[3 * r + c]);
  T.t = {static_cast<float>(p.t[0]), static_cast<float>(p.t[1]), static_cast<float>(p.t[2])};
  return T;
}

// Solves J^T J x = -J^T r by Cholesky (the system is symmetric positive definite whenever it is
// solvable at all). False when a pivot is not positive or the result is not finite. It runs in one
// GPU thread per Gauss-Newton step, on the critical path: one reciprocal square root per pivot,
// then only multiplications (double sqrt and division are long instruction sequences on the GPU).
SEAMLESS_HD inline bool solve_normal_equations(const IcpSums& s, double x[6]) {
  // Every loop fully unrolled: constant indices keep the arrays in registers (a run-time index
  // would put them in local memory).
  double L[6][6], inv[6];  // the lower triangle of J^T J, overwritten column by column by its factor
#pragma unroll
  for (int i = 0; i < 6; ++i)
#pragma unroll
    for (int j = i; j < 6; ++j) L[j][i] = s.jtj[i * 6 - i * (i - 1) / 2 + (j - i)];  // row i of the upper triangle
#pragma unroll
  for (int j = 0; j < 6; ++j) {
    double d = L[j][j];
#pragma unroll
    for (int k = 0; k < j; ++k) d -= L[j][k] * L[j][k];
    if (!(d > 0.0)) return false;
    inv[j] = rsqrt_d(d);
    L[j][j] = d * inv[j];
#pragma unroll
    for (int i = j + 1; i < 6; ++i) {
      double v = L[i][j];
#pragma unroll
      for (int k = 0; k < j; ++k) v -= L[i][k] * L[j][k];
      L[i][j] = v * inv[j];
    }
  }
#pragma unroll
  for (int i = 0; i < 6; ++i) {  // L y = -J^T r, y in x
    double v = -s.jtr[i];
#pragma unroll
    for (int k = 0; k < i; ++k) v -= L[i][k] * x[k];
    x[i] = v * inv[i];
  }
#pragma unroll
  for (int i = 5; i >= 0; --i) {  // L^T x = y, in place (x[k > i] are final, x[i] still y[i])
    double v = x[i];
#pragma unroll
    for (int k = i + 1; k < 6; ++k) v -= L[k][i] * x[k];
    x[i] = v * inv[i];
  }
#pragma unroll
  for (int i = 0; i < 6; ++i)
    if (!is_finite(x[i])) return false;
  return true;
}

// p <- exp(xi) p with exp(xi) = (Rodrigues rotation of omega, translation upsilon): the left
// update of the header comment, first order in xi like KinectFusion eq. 19, kept exactly rigid.
SEAMLESS_HD inline void left_update(IcpPose& p, const double xi[6]) {
  const double th2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2];
  double D[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (th2 > 0.0) {
    const double r = rsqrt_d(th2), th = th2 * r, k[3] = {xi[0] * r, xi[1] * r, xi[2] * r};
    const double s = sin(th), c = 1.0 - cos(th);  // nvcc merges the two into one sincos
    // R = I + sin(th) K + (1 - cos(th)) K^2, K the cross-product matrix of the unit axis k.
    D[0] = 1 - c * (k[1] * k[1] + k[2] * k[2]), D[1] = -s * k[2] + c * k[0] * k[1], D[2] = s * k[1] + c * k[0] * k[2];
    D[3] = s * k[2] + c * k[0] * k[1], D[4] = 1 - c * (k[0] * k[0] + k[2] * k[2]), D[5] = -s * k[0] + c * k[1] * k[2];
    D[6] = -s * k[1] + c * k[0] * k[2], D[7] = s * k[0] + c * k[1] * k[2], D[8] = 1 - c * (k[0] * k[0] + k[1] * k[1]);
  }
  double R[9], t[3];
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      R[3 * r + c] = D[3 * r] * p.R[c] + D[3 * r + 1] * p.R[3 + c] + D[3 * r + 2] * p.R[6 + c];
    t[r] = D[3 * r] * p.t[0] + D[3 * r + 1] * p.t[1] + D[3 * r + 2] * p.t[2] + xi[3 + r];
  }
  for (int i = 0; i < 9; ++i) p.R[i] = R[i];
  for (int i = 0; i < 3; ++i) p.t[i] = t[i];
}

// What a reduction does with its system once summed: nothing, or one Gauss-Newton step on *pose.
enum class IcpUpdate { none, step, first_step };

// True when a step of this level has nothing left to do: the level stalled (the same estimate
// would give the same failing system again) or converged.
SEAMLESS_HD inline bool level_done(const IcpPose& p) { return p.stalled || p.converged; }

// One Gauss-Newton step: solves the system s and applies the update to p; first_step (a level's
// first) clears the stall and convergence of the previous level. A step xi = (omega, upsilon)
// smaller than L's stop thresholds marks the level converged; a failed solve marks it stalled.
SEAMLESS_HD inline void gauss_newton_update(const IcpSums& s, IcpPose& p, IcpUpdate u, const IcpLevel& L) {
  if (u == IcpUpdate::none) return;
  if (u == IcpUpdate::first_step) p.stalled = p.converged = 0;
  ++p.steps;
  double xi[6];
  if (!solve_normal_equations(s, xi)) {
    p.stalled = 1;
    return;
  }
  left_update(p, xi);
  const double rot2 = xi[0] * xi[0] + xi[1] * xi[1] + xi[2] * xi[2];
  const double tra2 = xi[3] * xi[3] + xi[4] * xi[4] + xi[5] * xi[5];
  const double sr = L.stop_rotation, st = L.stop_translation;
  p.converged = rot2 < sr * sr && tra2 < st * st;
}

// The step of round `step` of a level's loop: its first clears the previous level's flags.
SEAMLESS_HD inline IcpUpdate level_step(int step) { return step == 0 ? IcpUpdate::first_step : IcpUpdate::step; }

template <Executor Exec> struct Icp {
  // Sums the point-to-plane normal equations over every pixel of the current level (one pass) at the
  // estimate *pose (level.ref_T_cur is ignored) into *out on the device, without a step (tests,
  // statistics).
  static void icp_reduce_into(const Exec& ex, IcpLevel level, IcpPose* pose, IcpSums* out);

  // Up to `steps` Gauss-Newton steps of one level in one device launch (transform_reduce_rounds):
  // each sums the system at *pose into *out and applies it (gauss_newton_update), and the steps end
  // once the level is done, so a converged level's remaining steps cost nothing. *out then holds the
  // last system summed. The host queues the whole coarse-to-fine loop, a launch per level.
  static void icp_level_steps(const Exec& ex, IcpLevel level, IcpPose* pose, IcpSums* out, int steps);

  // Moves vertex and normal maps into another frame (x -> T x, n -> R n); invalid pixels stay zero.
  // Used to express a world-space raycast in the coordinates of the camera it was rendered from.
  static void transform_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, SE3 T, View2D<vec3> vout,
                             View2D<vec3> nout);

  // Half-resolution vertex and normal maps of a model prediction (KinectFusion builds the model
  // pyramid by subsampling the raycast): mean of the 2x2 block's valid pixels whose depth is within
  // max_diff of the block's first valid pixel; the normal is the renormalised mean normal.
  static void pyr_down_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, View2D<vec3> vout,
                            View2D<vec3> nout, float max_diff);
};

}  // namespace seamless::kernels
