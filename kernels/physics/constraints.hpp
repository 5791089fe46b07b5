// Per-constraint math of the unified solver (host and device). Each function returns the
// position correction of one particle; the kernels of the physics families gather these per particle
// (Jacobi, Macklin 2014 section 4.2), so that no two threads write the same particle.
#pragma once
#include "core/hd.hpp"
#include "core/math.hpp"

namespace seamless::kernels {

// Contact along unit normal n (pointing from the other body to particle i) with penetration
// depth > 0, plus Coulomb friction at the position level (Macklin 2014, section 6.1, eqs. 23-24):
// the relative tangential displacement over the step is removed entirely while it is below
// mu_s * depth (static friction), otherwise reduced by mu_k * depth (kinetic friction).
// rel = (p_i - x_i) - (p_j - x_j); wj = 0 for static geometry. Mass-weighted split (eq. 4.3).
SEAMLESS_HD inline vec3 contact_delta(vec3 n, float depth, vec3 rel, float wi, float wj, float mu_s, float mu_k) {
  float ws = wi + wj;
  if (!(ws > 0.f)) return {0.f, 0.f, 0.f};
  vec3 d = n * depth;
  vec3 t = rel - n * dot(rel, n);
  float tl = length(t);
  if (tl > 0.f) {
    if (tl < mu_s * depth) d -= t;
    else d -= t * fminf(mu_k * depth / tl, 1.f);
  }
  return d * (wi / ws);
}

// Distance constraint C = |p_i - p_j| - L (Mueller 2007, eq. 4.7/4.8): correction of p_i.
SEAMLESS_HD inline vec3 distance_delta(vec3 pi, vec3 pj, float wi, float wj, float L, float k) {
  float ws = wi + wj;
  vec3 d = pi - pj;
  float l = length(d);
  if (!(ws > 0.f) || l < 1e-12f) return {0.f, 0.f, 0.f};
  return d * (-k * (wi / ws) * (l - L) / l);
}

// Strain limit (Provot 1995, section 5): correction of p_i that brings |p_i - p_j| back into
// [(1 - limit) L, (1 + limit) L] (the nearer bound), mass-weighted and over-relaxed by omega in
// [1, 2) (the edge ends omega - 1 times its excess inside the band, which speeds up Gauss-Seidel
// along chains of limited edges); zero inside the band.
SEAMLESS_HD inline vec3 strain_limit_delta(vec3 pi, vec3 pj, float wi, float wj, float L, float limit, float omega) {
  vec3 d = pi - pj;
  float l = length(d), lo = (1.f - limit) * L, hi = (1.f + limit) * L;
  float target = l > hi ? hi : l < lo ? lo : l;
  float ws = wi + wj;
  if (target == l || !(ws > 0.f) || l < 1e-12f) return {0.f, 0.f, 0.f};
  return d * (-(wi / ws) * omega * (l - target) / l);
}

// Dihedral bending constraint (Mueller 2007, eq. 4.9 and appendix A): p[0], p[1] share the edge,
// p[2], p[3] are the opposite vertices; phi0 is the rest angle. Writes the corrections of all
// four vertices to out[0..3].
SEAMLESS_HD inline void bending_deltas(const vec3* p, const float* w, float phi0, float k, vec3* out) {
  for (int i = 0; i < 4; ++i) out[i] = {0.f, 0.f, 0.f};
  vec3 p2 = p[1] - p[0], p3 = p[2] - p[0], p4 = p[3] - p[0];
  vec3 c23 = cross(p2, p3), c24 = cross(p2, p4);
  float l23 = length(c23), l24 = length(c24);
  if (l23 < 1e-12f || l24 < 1e-12f) return;
  vec3 n1 = c23 / l23, n2 = c24 / l24;
  float d = fminf(fmaxf(dot(n1, n2), -1.f), 1.f);
  vec3 q[4];
  q[2] = (cross(p2, n2) + cross(n1, p2) * d) / l23;
  q[3] = (cross(p2, n1) + cross(n2, p2) * d) / l24;
  q[1] = -(cross(p3, n2) + cross(n1, p3) * d) / l23 - (cross(p4, n1) + cross(n2, p4) * d) / l24;
  q[0] = -q[1] - q[2] - q[3];
  float den = 0.f;
  for (int i = 0; i < 4; ++i) den += w[i] * length2(q[i]);
  if (den < 1e-12f) return;
  float s = sqrtf(fmaxf(1.f - d * d, 0.f)) * (acosf(d) - phi0) / den;
  for (int i = 0; i < 4; ++i) out[i] = q[i] * (-k * w[i] * s);
}

// Aerodynamic force on one triangle (Keckeisen 2004; dissertation eqs. 4.10-4.11), to be shared
// equally by its three vertices. vrel = mean vertex velocity minus the wind.
SEAMLESS_HD inline vec3 triangle_aero_force(vec3 p0, vec3 p1, vec3 p2, vec3 vrel, float drag, float lift, float rho) {
  vec3 c = cross(p1 - p0, p2 - p0);
  float cl = length(c), vl = length(vrel);
  if (cl < 1e-12f || vl < 1e-6f) return {0.f, 0.f, 0.f};
  float area = 0.5f * cl;
  vec3 n = c / cl, vd = vrel / vl;
  float cos_t = dot(n, vd);
  if (cos_t < 0.f) {
    n = -n;
    cos_t = -cos_t;
  }
  float q = 0.5f * rho * vl * vl * area;
  vec3 f = vd * (-drag * q * cos_t);  // drag opposes the motion, scaled by exposure
  vec3 u = cross(cross(n, vd), vd);   // in the plane of n and v, normal to v
  float ul = length(u);
  if (ul > 1e-9f) f += (u / ul) * (lift * q * cos_t * sqrtf(fmaxf(1.f - cos_t * cos_t, 0.f)));
  return f;
}

}  // namespace seamless::kernels
