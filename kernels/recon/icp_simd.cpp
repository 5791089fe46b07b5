// The CPU's ICP terms on 8 lanes (icp_simd.hpp): icp_pixel_terms (icp.inl) for 8 consecutive
// pixels at once, lane l pixel begin + l, each lane computed with the scalar code's expressions.
#include "kernels/recon/icp_simd.hpp"

#include "core/simd.hpp"

#if SEAMLESS_SIMD_X86
#include <immintrin.h>
#endif

namespace seamless::kernels {

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {

using simd::i8, simd::f8, simd::vf, simd::vi, simd::vm, simd::v3;

namespace {

// Lane l: p[idx[l]] where m holds, 0 elsewhere.
SEAMLESS_SIMD_INL vf gather(const float* p, i8 idx, vm m) {
#if SEAMLESS_SIMD_X86
  return reinterpret_cast<f8>(_mm256_mask_i32gather_ps(_mm256_setzero_ps(), p, reinterpret_cast<__m256i>(idx),
                                                       reinterpret_cast<__m256>(m.v), 4));
#else
  vf r(0.f);
  for (int l = 0; l < simd::kWidth; ++l)
    if (m.v[l]) r.v[l] = p[idx[l]];
  return r;
#endif
}

// Lane l: a[e[l]] where m holds, zero elsewhere.
SEAMLESS_SIMD_INL v3 gather_v3(const vec3* a, i8 e, vm m) {
  const float* f = reinterpret_cast<const float*>(a);
  const i8 i = e * 3;
  return {gather(f, i, m), gather(f, i + 1, m), gather(f, i + 2, m)};
}

// valid_point and valid_normal lane by lane.
SEAMLESS_SIMD_INL vm valid_points(v3 v) { return v.z > vf(0.f); }
SEAMLESS_SIMD_INL vm valid_normals(v3 n) { return {(n.x.v != f8{}) | (n.y.v != f8{}) | (n.z.v != f8{})}; }

// R v lane by lane, row by row as mat3's operator* (dot(row, v)).
SEAMLESS_SIMD_INL v3 rotate(const mat3& R, v3 v) {
  return {dot(simd::broadcast(R.row(0)), v), dot(simd::broadcast(R.row(1)), v), dot(simd::broadcast(R.row(2)), v)};
}

// Entry e of a view (pitch * y + x) as a 32-bit lane: add_icp_terms_simd's caller checks that
// every entry of the views fits (icp_simd_usable).
SEAMLESS_SIMD_INL i8 entries(View2D<const vec3> v, i8 x, i8 y) { return y * static_cast<int>(v.pitch) + x; }

// The terms of lanes ok (a correspondence each): add_point_to_plane's rows, w = 1, as add_row
// writes them into a pixel's zeroed IcpTerms.
struct LaneTerms {
  vf jtj[21], jtr[6], error;
};
SEAMLESS_SIMD_INL void point_to_plane_terms(v3 q, v3 v, v3 n, LaneTerms& t) {
  const v3 a = cross(q, n);
  const vf r = dot(n, q - v), w(1.f), zero(0.f);
  const vf J[6] = {a.x, a.y, a.z, n.x, n.y, n.z};
  for (int i = 0; i < 6; ++i) {
    const vf wi = w * J[i];
    for (int j = i; j < 6; ++j) t.jtj[i * 6 - i * (i - 1) / 2 + (j - i)] = zero + wi * J[j];
    t.jtr[i] = zero + wi * r;
  }
  t.error = zero + w * r * r;
}

}  // namespace

void add_icp_terms_simd(const IcpLevel& L, const SE3& T, std::int64_t begin, std::int64_t end, IcpSums& s) {
  if (begin >= end) return;
  const int st = L.stride, ws = (L.cur_vertex.width + st - 1) / st;
  const Intrinsics& K = L.K;
  const v3 t = simd::broadcast(T.t);
  int ix = static_cast<int>(begin % ws), iy = static_cast<int>(begin / ws);  // level_pixel of pixel i, kept
  for (std::int64_t i = begin; i < end; i += simd::kWidth) {
    const int n = end - i < simd::kWidth ? static_cast<int>(end - i) : simd::kWidth;
    i8 x, y;
    for (int l = 0; l < simd::kWidth; ++l) {
      x[l] = st * ix, y[l] = st * iy;
      if (++ix == ws) ix = 0, ++iy;
    }
    const vm live = simd::from_bits((1 << n) - 1);
    // find_correspondence, its tests in its order (a lane that fails one is out).
    const v3 p = gather_v3(L.cur_vertex.data, entries(L.cur_vertex, x, y), live);
    const v3 np = gather_v3(L.cur_normal.data, entries(L.cur_normal, x, y), live);
    const vm valid = live & valid_points(p);
    vm ok = valid & valid_normals(np);
    if (L.max_depth > 0.f) ok = ok & !(p.z > vf(L.max_depth));
    const v3 q = rotate(T.R, p) + t;
    ok = ok & !(q.z <= vf(0.f));
    const vi u = simd::floor_int(vf(K.fx) * q.x / q.z + vf(K.cx) + vf(0.5f));
    const vi v = simd::floor_int(vf(K.fy) * q.y / q.z + vf(K.cy) + vf(0.5f));
    ok = ok & (u >= vi(0)) & (v >= vi(0)) & (u < vi(L.ref_vertex.width)) & (v < vi(L.ref_vertex.height));
    const v3 cv = gather_v3(L.ref_vertex.data, entries(L.ref_vertex, u.v, v.v), ok);
    const v3 cn = gather_v3(L.ref_normal.data, entries(L.ref_normal, u.v, v.v), ok);
    ok = ok & valid_points(cv) & valid_normals(cn);
    if (L.max_depth > 0.f) ok = ok & !(cv.z > vf(L.max_depth));
    ok = ok & !(length2(q - cv) > vf(L.dist_threshold * L.dist_threshold));
    ok = ok & (dot(rotate(T.R, np), cn) >= vf(L.cos_angle));
    const int valid_bits = simd::bits(valid), ok_bits = simd::bits(ok);
    LaneTerms terms;
    if (ok_bits) point_to_plane_terms(q, cv, cn, terms);
    // transform_reduce's local = local + icp_pixel_terms(i), pixel by pixel; a pixel without a
    // correspondence adds zeros there, which change no sum.
    for (int l = 0; l < n; ++l) {
      if (valid_bits >> l & 1) s.valid = s.valid + 1.0;
      if (!(ok_bits >> l & 1)) continue;
      for (int k = 0; k < 21; ++k) s.jtj[k] = s.jtj[k] + static_cast<double>(terms.jtj[k][l]);
      for (int k = 0; k < 6; ++k) s.jtr[k] = s.jtr[k] + static_cast<double>(terms.jtr[k][l]);
      s.error = s.error + static_cast<double>(terms.error[l]);
      s.inliers = s.inliers + 1.0;
    }
  }
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
