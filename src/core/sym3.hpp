// Symmetric 3 x 3 matrices by their six distinct entries, and their eigen decomposition (host and
// device): the anisotropic kernels' covariances (kernels/physics/anisotropy.hpp).
#pragma once
#include <cmath>

#include "core/basis.hpp"
#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless {

struct sym3 {
  float xx, xy, xz, yy, yz, zz;
  SEAMLESS_HD static sym3 zero() { return {0.f, 0.f, 0.f, 0.f, 0.f, 0.f}; }
};
SEAMLESS_HD inline sym3 operator+(const sym3& a, const sym3& b) {
  return {a.xx + b.xx, a.xy + b.xy, a.xz + b.xz, a.yy + b.yy, a.yz + b.yz, a.zz + b.zz};
}
SEAMLESS_HD inline sym3 operator*(const sym3& a, float s) {
  return {a.xx * s, a.xy * s, a.xz * s, a.yy * s, a.yz * s, a.zz * s};
}
// a a^T
SEAMLESS_HD inline sym3 sym_outer(vec3 a) { return {a.x * a.x, a.x * a.y, a.x * a.z, a.y * a.y, a.y * a.z, a.z * a.z}; }
SEAMLESS_HD inline vec3 operator*(const sym3& a, vec3 v) {
  return {a.xx * v.x + a.xy * v.y + a.xz * v.z, a.xy * v.x + a.yy * v.y + a.yz * v.z,
          a.xz * v.x + a.yz * v.y + a.zz * v.z};
}

// A = V diag(e) V^T for a symmetric A: e its eigenvalues (in no particular order), V's columns
// orthonormal eigenvectors. Not iterative (the trigonometric method of Smith 1961, "Eigenvalues of
// a symmetric 3 x 3 matrix", CACM 4(4); Kopp 2008, "Efficient numerical diagonalization of
// hermitian 3x3 matrices", with Eberly's robust eigenvectors, "A Robust Eigensolver for 3 x 3
// Symmetric Matrices", 2014), and exact to float rounding for every A, repeated eigenvalues
// included:
// - B = (A - q I) / p with q = tr(A) / 3 and p^2 = tr((A - q I)^2) / 6 has trace 0 and
//   tr(B^2) = 6, so its characteristic polynomial is b^3 - 3 b - det(B) and its eigenvalues lie in
//   [-2, 2]. With r = |det(B)| / 2 <= 1, the largest root of b^3 - 3 b - 2 r is 2 cos(acos(r) / 3)
//   in [sqrt(3), 2]; here it comes from Newton's method (below) instead of acos and cos.
// - That root (times the sign of det(B)) is the eigenvalue farthest from the other two: both lie at
//   least sqrt(3) away from it. Its eigenvector is then well conditioned, the longest cross
//   product of two rows of B - b I (the columns of the adjugate (b1 - b) (b2 - b) v v^T, the
//   longest of squared length >= 3, so never near zero).
// - The other two, however close (an isotropic neighbourhood with a little noise, or a disc's two
//   equal in-plane axes), come from one Jacobi rotation (Golub & Van Loan 8.4.2, sym.schur2) of B
//   restricted to the plane normal to that eigenvector: exact for the 2 x 2 problem, where the
//   trigonometric eigenvalues of a nearly repeated pair lose half their digits (the acos of a value
//   near 1) and cross products of near-parallel rows lose their direction.
// An A within float rounding of q I (p below 1e-7 q) is returned as its diagonal and the axes.
SEAMLESS_HD inline void eigen_sym3(const sym3& A, mat3& V, vec3& e) {
  const float q = (A.xx + A.yy + A.zz) * (1.f / 3.f);
  const float bxx = A.xx - q, byy = A.yy - q, bzz = A.zz - q;
  const float p2 = (bxx * bxx + byy * byy + bzz * bzz + 2.f * (A.xy * A.xy + A.xz * A.xz + A.yz * A.yz)) * (1.f / 6.f);
  if (!(p2 > 1e-14f * q * q)) {  // also A = 0 (p2 = q = 0)
    V = mat3::identity();
    e = {A.xx, A.yy, A.zz};
    return;
  }
  const float p = sqrtf(p2), ip = 1.f / p;
  const sym3 B{bxx * ip, A.xy * ip, A.xz * ip, byy * ip, A.yz * ip, bzz * ip};
  const float det =
      B.xx * (B.yy * B.zz - B.yz * B.yz) - B.xy * (B.xy * B.zz - B.yz * B.xz) + B.xz * (B.xy * B.yz - B.yy * B.xz);
  const float r = fminf(0.5f * fabsf(det), 1.f);
  // Newton's method on f(b) = b^3 - 3 b - 2 r from the tangent at r = 1 of the root as a function
  // of r (concave, so the tangent lies above it, by at most 0.046 at r = 0): f is convex and
  // increasing on [sqrt(3), 2], so the iterates fall monotonically onto the root, and each squares
  // the error (0.046, 2e-3, 3e-6, 1e-11).
  float b = (16.f + 2.f * r) * (1.f / 9.f);
  for (int it = 0; it < 3; ++it) b -= (b * (b * b - 3.f) - 2.f * r) / (3.f * (b * b - 1.f));
  b = det < 0.f ? -b : b;
  // Its eigenvector: the longest cross product of two rows of B - b I.
  const vec3 r0{B.xx - b, B.xy, B.xz}, r1{B.xy, B.yy - b, B.yz}, r2{B.xz, B.yz, B.zz - b};
  vec3 v = cross(r0, r1);
  float vv = length2(v);
  const vec3 c02 = cross(r0, r2), c12 = cross(r1, r2);
  const float d02 = length2(c02), d12 = length2(c12);
  if (d02 > vv) v = c02, vv = d02;
  if (d12 > vv) v = c12, vv = d12;
  v = v * (1.f / sqrtf(vv));
  // The other two: B in the plane of u, w normal to v, and the rotation that diagonalises it.
  vec3 u, w;
  orthonormal_basis(v, u, w);
  const vec3 Bu = B * u, Bw = B * w;
  const float buu = dot(u, Bu), buw = dot(u, Bw), bww = dot(w, Bw);
  float t = 0.f;  // tan of the rotation angle
  if (buw != 0.f) {
    const float tau = (bww - buu) / (2.f * buw);
    t = (tau >= 0.f ? 1.f : -1.f) / (fabsf(tau) + sqrtf(tau * tau + 1.f));
  }
  const float c = 1.f / sqrtf(t * t + 1.f), s = t * c;
  const vec3 v1 = c * u - s * w, v2 = s * u + c * w;
  V = {{{v.x, v1.x, v2.x}, {v.y, v1.y, v2.y}, {v.z, v1.z, v2.z}}};
  e = {q + p * b, q + p * (buu - t * buw), q + p * (bww + t * buw)};
}

}  // namespace seamless
