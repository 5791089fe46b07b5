// Point-to-plane ICP after KinectFusion (Newcombe et al. 2011, section 3.5): projective data
// association, rejection by distance and normal angle, and the 6x6 normal equations of one
// Gauss-Newton step summed over all pixels in a single device reduction. The host solves them.
//
// Parametrisation (the "small-angle" linearisation of KinectFusion eq. 16-19): the current estimate
// ref_T_cur is updated on the left, ref_T_cur <- exp(xi) ref_T_cur with xi = (omega, upsilon), so a
// point q = ref_T_cur p moves to q + omega x q + upsilon. The point-to-plane residual of a pair
// (q, reference vertex v, reference normal n) is r = n . (q - v), and its Jacobian is
// J = [ (q x n)^T, n^T ]  (d/d omega of n . (omega x q) = omega . (q x n)).
#pragma once
#include <cstdint>

#include "core/camera.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// One Gauss-Newton system: upper triangle of J^T W J (row-major, 21 entries), J^T W r (6), the sum of
// weighted squared residuals, and counts. Doubles: 300k pixels of float products summed in float
// lose digits the 6x6 solve needs. Default-constructed to zero (value-initialised by the reduce).
struct IcpSums {
  double jtj[21];
  double jtr[6];
  double error;    // sum w r^2
  double inliers;  // geometric correspondences accepted
  double valid;    // current pixels with a vertex (the denominator of the inlier ratio)
};

SEAMLESS_HD inline IcpSums operator+(const IcpSums& a, const IcpSums& b) {
  IcpSums s;
  for (int k = 0; k < 21; ++k) s.jtj[k] = a.jtj[k] + b.jtj[k];
  for (int k = 0; k < 6; ++k) s.jtr[k] = a.jtr[k] + b.jtr[k];
  s.error = a.error + b.error;
  s.inliers = a.inliers + b.inliers;
  s.valid = a.valid + b.valid;
  return s;
}

// Adds one residual row r with Jacobian J = [a^T, b^T] (6 entries) and weight w.
SEAMLESS_HD inline void add_row(IcpSums& s, vec3 a, vec3 b, float r, float w) {
  const float J[6] = {a.x, a.y, a.z, b.x, b.y, b.z};
  int k = 0;
  for (int i = 0; i < 6; ++i) {
    const double wi = static_cast<double>(w) * J[i];
    for (int j = i; j < 6; ++j) s.jtj[k++] += wi * J[j];
    s.jtr[i] += wi * r;
  }
  s.error += static_cast<double>(w) * r * r;
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
};

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
  c.q = L.ref_T_cur * p;
  if (c.q.z <= 0.f) return false;
  c.uv = L.K.project(c.q);
  int u = static_cast<int>(floorf(c.uv.x + 0.5f)), v = static_cast<int>(floorf(c.uv.y + 0.5f));
  if (!L.ref_vertex.inside(u, v)) return false;
  c.v = L.ref_vertex(u, v);
  c.n = L.ref_normal(u, v);
  if (!valid_point(c.v) || !valid_normal(c.n)) return false;
  if (length2(c.q - c.v) > L.dist_threshold * L.dist_threshold) return false;
  return dot(L.ref_T_cur.rotate(np), c.n) >= L.cos_angle;
}

// The point-to-plane row of a correspondence (see the header comment).
SEAMLESS_HD inline void add_point_to_plane(IcpSums& s, const Correspondence& c, float w) {
  add_row(s, cross(c.q, c.n), c.n, dot(c.n, c.q - c.v), w);
  s.inliers += 1.0;
}

// Sums the point-to-plane normal equations over every pixel of the current level (one pass).
template <class Exec>
IcpSums icp_reduce(const Exec& ex, IcpLevel level);

// Moves vertex and normal maps into another frame (x -> T x, n -> R n); invalid pixels stay zero.
// Used to express a world-space raycast in the coordinates of the camera it was rendered from.
template <class Exec>
void transform_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, SE3 T, View2D<vec3> vout,
                    View2D<vec3> nout);

// Half-resolution vertex and normal maps of a model prediction (KinectFusion builds the model
// pyramid by subsampling the raycast): mean of the 2x2 block's valid pixels whose depth is within
// max_diff of the block's first valid pixel; the normal is the renormalised mean normal.
template <class Exec>
void pyr_down_maps(const Exec& ex, View2D<const vec3> vin, View2D<const vec3> nin, View2D<vec3> vout,
                   View2D<vec3> nout, float max_diff);

}  // namespace seamless::kernels
