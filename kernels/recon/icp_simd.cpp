// The CPU's ICP and RGB-D terms on 8 lanes (icp_simd.hpp): icp_pixel_terms (icp.inl) and
// rgbd_pixel_terms (rgbd.inl) for 8 consecutive pixels at once, lane l pixel begin + l, each lane
// computed with the scalar code's expressions in their order.
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
// every entry of the views fits (icp_on_lanes).
SEAMLESS_SIMD_INL i8 entries(View2D<const vec3> v, i8 x, i8 y) { return y * static_cast<int>(v.pitch) + x; }

// The rows' sums of one pixel, as add_row writes them into its zeroed terms: first_row puts the row
// (J, r, w) where m holds (zeros elsewhere), add_row_lanes adds a second one where m holds.
struct LaneTerms {
  vf jtj[21], jtr[6], error;
};
SEAMLESS_SIMD_INL void first_row(const vf J[6], vf r, vf w, vm m, LaneTerms& t) {
  const vf zero(0.f);
  for (int i = 0; i < 6; ++i) {
    const vf wi = w * J[i];
    for (int j = i; j < 6; ++j) t.jtj[i * 6 - i * (i - 1) / 2 + (j - i)] = select(m, zero + wi * J[j], zero);
    t.jtr[i] = select(m, zero + wi * r, zero);
  }
  t.error = select(m, zero + w * r * r, zero);
}
SEAMLESS_SIMD_INL void add_row_lanes(const vf J[6], vf r, vf w, vm m, LaneTerms& t) {
  for (int i = 0; i < 6; ++i) {
    const vf wi = w * J[i];
    for (int j = i; j < 6; ++j) {
      vf& e = t.jtj[i * 6 - i * (i - 1) / 2 + (j - i)];
      e = select(m, e + wi * J[j], e);
    }
    t.jtr[i] = select(m, t.jtr[i] + wi * r, t.jtr[i]);
  }
  t.error = select(m, t.error + w * r * r, t.error);
}

// s += lane l's terms (a pixel with a row); transform_reduce's local = local + terms, component
// by component.
SEAMLESS_SIMD_INL void add_lane(IcpSums& s, const LaneTerms& t, int l) {
  for (int k = 0; k < 21; ++k) s.jtj[k] = s.jtj[k] + static_cast<double>(t.jtj[k][l]);
  for (int k = 0; k < 6; ++k) s.jtr[k] = s.jtr[k] + static_cast<double>(t.jtr[k][l]);
  s.error = s.error + static_cast<double>(t.error[l]);
}

// find_correspondence (icp.hpp) for 8 pixels: its tests in its order, all but the last (the
// normal angle, whose dot product is `angle`), a lane that fails one is out of `found`.
struct LaneCorrespondences {
  i8 x, y;     // the pixels
  vm valid;    // valid_point(cur_vertex(x, y))
  vm found;    // every test but the normal angle passed
  v3 q, v, n;  // Correspondence's q, v and n
  vf ux, uy;   // Correspondence's uv
  vf angle;    // dot(ref_T_cur.rotate(cur_normal(x, y)), n)
};
SEAMLESS_SIMD_INL LaneCorrespondences correspondences(const IcpLevel& L, const SE3& T, i8 x, i8 y, vm live) {
  const Intrinsics& K = L.K;
  LaneCorrespondences c;
  c.x = x, c.y = y;
  const v3 p = gather_v3(L.cur_vertex.data, entries(L.cur_vertex, x, y), live);
  const v3 np = gather_v3(L.cur_normal.data, entries(L.cur_normal, x, y), live);
  c.valid = live & valid_points(p);
  vm ok = c.valid & valid_normals(np);
  if (L.max_depth > 0.f) ok = ok & !(p.z > vf(L.max_depth));
  c.q = rotate(T.R, p) + simd::broadcast(T.t);
  ok = ok & !(c.q.z <= vf(0.f));
  c.ux = vf(K.fx) * c.q.x / c.q.z + vf(K.cx), c.uy = vf(K.fy) * c.q.y / c.q.z + vf(K.cy);
  const vi u = simd::floor_int(c.ux + vf(0.5f)), v = simd::floor_int(c.uy + vf(0.5f));
  ok = ok & (u >= vi(0)) & (v >= vi(0)) & (u < vi(L.ref_vertex.width)) & (v < vi(L.ref_vertex.height));
  c.v = gather_v3(L.ref_vertex.data, entries(L.ref_vertex, u.v, v.v), ok);
  c.n = gather_v3(L.ref_normal.data, entries(L.ref_normal, u.v, v.v), ok);
  ok = ok & valid_points(c.v) & valid_normals(c.n);
  if (L.max_depth > 0.f) ok = ok & !(c.v.z > vf(L.max_depth));
  ok = ok & !(length2(c.q - c.v) > vf(L.dist_threshold * L.dist_threshold));
  c.found = ok;
  c.angle = dot(rotate(T.R, np), c.n);
  return c;
}

// Calls f(x, y, live, n) for the pixels begin .. end - 1 of level L, 8 at a time: level_pixel's
// pixels, lane l pixel i + l, the n lanes `live` below end.
template <class F>
SEAMLESS_SIMD_INL void for_pixel_lanes(const IcpLevel& L, std::int64_t begin, std::int64_t end, F f) {
  const int st = L.stride, ws = (L.cur_vertex.width + st - 1) / st;
  int ix = static_cast<int>(begin % ws), iy = static_cast<int>(begin / ws);  // level_pixel of pixel i, kept
  for (std::int64_t i = begin; i < end; i += simd::kWidth) {
    const int n = end - i < simd::kWidth ? static_cast<int>(end - i) : simd::kWidth;
    i8 x, y;
    for (int l = 0; l < simd::kWidth; ++l) {
      x[l] = st * ix, y[l] = st * iy;
      if (++ix == ws) ix = 0, ++iy;
    }
    f(x, y, simd::from_bits((1 << n) - 1), n);
  }
}

// bilinear (rgbd.hpp) lane by lane for the lanes of m: the value, and the lanes whose four pixels
// have readings.
SEAMLESS_SIMD_INL vf bilinear_lanes(View2D<const float> im, vf x, vf y, vm m, vm& ok) {
  const vi x0 = simd::floor_int(x), y0 = simd::floor_int(y);
  const vf ax = x - vf(__builtin_convertvector(x0.v, f8)), ay = y - vf(__builtin_convertvector(y0.v, f8));
  const i8 e = y0.v * static_cast<int>(im.pitch) + x0.v, down = e + static_cast<int>(im.pitch);
  const vf a = gather(im.data, e, m), b = gather(im.data, e + 1, m), c = gather(im.data, down, m),
           d = gather(im.data, down + 1, m);
  const vf one(1.f);
  ok = m & (a >= vf(0.f)) & (b >= vf(0.f)) & (c >= vf(0.f)) & (d >= vf(0.f));
  return (one - ay) * ((one - ax) * a + ax * b) + ay * ((one - ax) * c + ax * d);
}

// photometric_residual (rgbd.hpp) for the lanes of m: r, g and the lanes that have one.
SEAMLESS_SIMD_INL vm photometric_lanes(const RgbdLevel& L, const LaneCorrespondences& c, vm m, vf& r, v3& g) {
  const Intrinsics& K = L.geo.K;
  const vf u = c.ux, v = c.uy, one(1.f);
  m = m & !(u < one) & !(v < one) & !(u >= vf(L.ref_intensity.width - 2.f)) & !(v >= vf(L.ref_intensity.height - 2.f));
  const vf cur = gather(L.cur_intensity.data, c.y * static_cast<int>(L.cur_intensity.pitch) + c.x, m);
  m = m & (cur >= vf(0.f));
  vm ok;
  const vf ref = bilinear_lanes(L.ref_intensity, u, v, m, ok);
  m = ok;
  r = ref - cur;
  m = m & !(simd::abs(r) > vf(L.max_intensity_diff));
  vm okxp, okxm, okyp, okym;
  const vf xp = bilinear_lanes(L.ref_intensity, u + one, v, m, okxp),
           xm = bilinear_lanes(L.ref_intensity, u - one, v, m, okxm),
           yp = bilinear_lanes(L.ref_intensity, u, v + one, m, okyp),
           ym = bilinear_lanes(L.ref_intensity, u, v - one, m, okym);
  m = okxp & okxm & okyp & okym;
  const vf gx = vf(0.5f) * (xp - xm), gy = vf(0.5f) * (yp - ym);
  m = m & !(gx * gx + gy * gy < vf(L.min_gradient * L.min_gradient));
  const vf iz = one / c.q.z;
  g = {gx * vf(K.fx) * iz, gy * vf(K.fy) * iz, -(gx * vf(K.fx) * c.q.x + gy * vf(K.fy) * c.q.y) * iz * iz};
  return m;
}

// t_weight (rgbd.hpp) lane by lane, at the variance var of every lane.
SEAMLESS_SIMD_INL vf t_weights(vf r, float var, float dof) {
  return var > 0.f ? vf(dof + 1.f) / (vf(dof) + r * r / vf(var)) : vf(1.f);
}

}  // namespace

void add_icp_terms_simd(const IcpLevel& L, const SE3& T, std::int64_t begin, std::int64_t end, IcpSums& s) {
  for_pixel_lanes(L, begin, end, [&](i8 x, i8 y, vm live, int n) {
    const LaneCorrespondences c = correspondences(L, T, x, y, live);
    const vm ok = c.found & (c.angle >= vf(L.cos_angle));
    const int valid_bits = simd::bits(c.valid), ok_bits = simd::bits(ok);
    LaneTerms terms;
    if (ok_bits) {  // add_point_to_plane: the geometric row, w = 1
      const v3 a = cross(c.q, c.n);
      const vf J[6] = {a.x, a.y, a.z, c.n.x, c.n.y, c.n.z};
      first_row(J, dot(c.n, c.q - c.v), vf(1.f), ok, terms);
    }
    // A pixel without a correspondence adds zeros to every sum but `valid`: no change.
    for (int l = 0; l < n; ++l) {
      if (valid_bits >> l & 1) s.valid = s.valid + 1.0;
      if (!(ok_bits >> l & 1)) continue;
      add_lane(s, terms, l);
      s.inliers = s.inliers + 1.0;
    }
  });
}

void add_rgbd_terms_simd(const RgbdLevel& R, const IcpPose& p, std::int64_t begin, std::int64_t end, RgbdSums& s) {
  const SE3 T = to_se3(p);
  const bool robust = R.dof > 0.f;
  for_pixel_lanes(R.geo, begin, end, [&](i8 x, i8 y, vm live, int n) {
    const LaneCorrespondences c = correspondences(R.geo, T, x, y, live);
    // find_rgbd_correspondence: with photometric_all_visible any normal angle finds one, and the
    // angle decides the geometric row only.
    const vm angle_ok = c.angle >= vf(R.geo.cos_angle);
    const vm found = R.photometric_all_visible ? c.found & (c.angle >= vf(-2.f)) : c.found & angle_ok;
    const vm mg = R.photometric_all_visible ? found & angle_ok : found;
    vf r(0.f);
    v3 g = simd::broadcast(vec3{0.f, 0.f, 0.f});
    const vm mp = simd::bits(found) ? photometric_lanes(R, c, found, r, g) : vm{i8{}};
    const int valid_bits = simd::bits(c.valid), g_bits = simd::bits(mg), p_bits = simd::bits(mp);
    if (!(g_bits | p_bits)) {
      for (int l = 0; l < n; ++l)
        if (valid_bits >> l & 1) s.icp.valid = s.icp.valid + 1.0;
      return;
    }
    // add_geometric_row
    const vf rg = dot(c.n, c.q - c.v);
    vf wg(R.geometric_weight), geo_wr2(0.f);
    if (robust) {
      const vf iz2 = R.depth_squared_noise ? vf(1.f) / (c.q.z * c.q.z) : vf(1.f);
      const vf rn = rg * iz2;
      wg = t_weights(rn, p.geo_var, R.dof);
      geo_wr2 = vf(0.f) + wg * rn * rn;
      wg = wg * (iz2 * iz2);
    }
    // add_rgbd_rows' photometric row
    vf wi(R.photometric_weight), photo_wr2(0.f);
    if (robust) {
      const vf t = t_weights(r, p.photo_var, R.dof);
      photo_wr2 = vf(0.f) + t * r * r;
      wi = wi * (t * vf(p.geo_var > 0.f && p.photo_var > 0.f ? p.geo_var / p.photo_var : 1.f));
    }
    const v3 a = cross(c.q, c.n), b = cross(c.q, g);
    const vf Jg[6] = {a.x, a.y, a.z, c.n.x, c.n.y, c.n.z}, Jp[6] = {b.x, b.y, b.z, g.x, g.y, g.z};
    LaneTerms terms;
    first_row(Jg, rg, wg, mg, terms);
    if (p_bits) add_row_lanes(Jp, r, wi, mp, terms);
    for (int l = 0; l < n; ++l) {
      if (valid_bits >> l & 1) s.icp.valid = s.icp.valid + 1.0;
      const bool has_g = g_bits >> l & 1, has_p = p_bits >> l & 1;
      if (!has_g && !has_p) continue;
      add_lane(s.icp, terms, l);
      if (has_g) s.icp.inliers = s.icp.inliers + 1.0;
      if (robust && has_g) s.geo_wr2 = s.geo_wr2 + static_cast<double>(geo_wr2[l]);
      if (robust && has_p) {
        s.photo_wr2 = s.photo_wr2 + static_cast<double>(photo_wr2[l]);
        s.photo_n = s.photo_n + 1.0;
      }
    }
  });
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
