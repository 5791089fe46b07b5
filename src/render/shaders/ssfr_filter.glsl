// SSFR smoothing (van der Laan et al. 2009, section 4.2), one axis per pass: run along x, then
// along y. Depth: the half-width is a world size projected at this pixel's depth, and empty
// pixels neither change nor contribute. Two edge-preserving modes:
//  - bilateral (the paper's cheaper alternative to curvature flow): Gaussian range weight.
//  - narrow range (Truong & Yuksel 2018, "A Narrow-Range Filter for Screen-Space Fluid
//    Rendering", section 3): samples further than the range mu behind the reference belong to
//    another surface and are left out; samples further than mu in front are clamped to
//    reference - mu, so that a nearer surface cannot pull this one forward, yet its edge still
//    smooths. mu = 3 range sigmas (where the bilateral weight has fallen to 1%).
// The range reference is the centre's tangent, not its depth. Truong & Yuksel compare every
// sample with the centre depth z: right for a surface facing the camera, wrong for one seen at a
// grazing angle, whose depth changes from one pixel to the next by more than mu allows over the
// kernel (a puddle on a table seen from 15 cm above, 0.6 m away: 5 mm per image row, so the
// samples beyond 6 rows, on one side, are dropped and on the other clamped). The filter then
// averages a one-sided, clamped set that changes abruptly from row to row: the surface breaks into
// horizontal bands, which the normals and the reflection show. Here each sample is compared with
// the depth the centre's tangent plane has at its pixel: a plane's inverse depth is affine in
// the image coordinates (1/z = a u + b v + c), so along the axis the reference is
// 1 / (1/z + k i), k the inverse depth's slope per texel at the centre (reference_slope). The
// result is the centre's inverse depth plus the weighted mean of the samples' inverse depths'
// differences from the reference's (after the range test, in depth: clamped or left out as
// above), i.e. the weighted mean of 1/s - k i. Where the window is symmetric (inside the
// surface) the k i terms cancel and this is the mean inverse depth, which does not depend on
// the estimated slope at all: at a grazing angle a pixel spans 1 mm across and 5 mm in depth, so
// a depth that followed the slope's estimate (noisy from column to column) would tilt the
// normals across the columns by tens of degrees. A plane's inverse depth being affine, its mean
// is the centre's (averaging depth instead would move a plane back by its perspective
// curvature, 3 mm at 0.6 m on the puddle); at the surface's rim, where the window is one-sided,
// the k i terms keep the rim on the tangent plane. A plane at any angle then passes unchanged
// and no sample of it is lost, while a
// depth discontinuity (a drop in front of the puddle, another layer behind it) is as far from the
// tangent as it is from the centre depth, and stays apart. The range itself is a height above the
// tangent plane, so in depth it grows as the surface turns away from the view (tangent_plane).
// Where the surface faces the camera this is exactly Truong & Yuksel's filter.
// Thickness (u_range_sigma <= 0, u_skip_empty false): no range weight; the half-width is the
// world size projected at the filtered fluid depth of the texel (u_width_depth, full resolution),
// so that the sum of chords is smoothed over the particle spacing at any distance: a spread layer
// would otherwise be thick at each particle and thin between them, a blotchy tint. Texels without
// fluid keep their value (the composite reads thickness only where there is fluid).
// The spatial weight is the biweight (1 - (i/r)^2)^2 over the half-width r (close to a Gaussian
// of sigma 0.38 r, and zero at the ends). Kernels wider than u_max_taps per side sample every
// k-th pixel on a lattice fixed to the image (the multiples of k): neighbouring pixels read the
// same texels with weights that shift smoothly, and a tap enters or leaves the window at weight
// zero, so the result varies smoothly from pixel to pixel. (Taps at multiples of k from each
// pixel instead split the pixels into k interleaved sets that read disjoint texels; wherever the
// depth is not smooth, at the spheres' silhouettes, their results differ and show as stripes one
// pixel apart in the normals.)
// Gap fill (depth only, u_fill_world > 0; the first iteration): a closing that checks depth. An
// empty texel between two fluid texels on this axis, their distance (world, at the farther one's
// depth) at most u_fill_world, whose depths agree within mu plus that distance (one surface,
// tilted up to 45 degrees to the view), takes their depth interpolated linearly, unless the scene
// is in front of that depth there (a real or virtual object between the particles). Particles
// that spread over a surface leave holes of a particle's size between their spheres; filled, the
// later passes smooth one surface over them instead of one bump per particle. Across a depth
// discontinuity (a drop in front of the puddle) nothing is filled.
// Lone drops (splat.glsl) are not part of the surface: a drop texel is kept as splatted (the
// drop's sphere, which the composite shades as a bead), and other texels neither average it in nor
// fill towards it.
// filter_at() is the pass at one texel; ssfr_filter.frag and ssfr_filter.comp run it.
uniform sampler2D u_src;
uniform ivec2 u_dir;            // (1, 0) or (0, 1)
uniform float u_world_radius;   // metres
uniform int u_max_px;
uniform int u_max_taps;
uniform float u_range_sigma;    // metres; <= 0 disables the range weight
uniform bool u_skip_empty;
uniform bool u_narrow_range;
uniform float u_fill_world;     // metres; 0: no gap fill
uniform sampler2D u_width_depth;    // thickness: the filtered fluid depth, full resolution
uniform sampler2D u_scene_depth_w;  // window depth of the scene (gap fill)

// The nearest fluid texel from p along -u_dir (side -1) or +u_dir (side 1), within n texels: its
// depth and distance in texels (0, 0: none).
vec2 nearest_fluid(ivec2 p, int side, int n) {
  ivec2 size = textureSize(u_src, 0);
  for (int i = 1; i <= n; ++i) {
    ivec2 q = p + side * i * u_dir;
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) break;
    float s = texelFetch(u_src, q, 0).r;
    if (s > 0.0 && !is_drop(s)) return vec2(s, float(i));
  }
  return vec2(0.0);
}

float fill_at(ivec2 p, float mu) {
  vec2 a = nearest_fluid(p, -1, u_max_px);
  if (a.x <= 0.0) return 0.0;  // most empty texels: no fluid on one side, half the search
  float f = u_dir.x != 0 ? u_K.x : u_K.y;
  // The span in texels is at most u_fill_world f / a.x (the span is measured at the farther depth).
  vec2 b = nearest_fluid(p, 1, min(u_max_px, int(u_fill_world * f / a.x - a.y)));
  if (b.x <= 0.0) return 0.0;
  float span = (a.y + b.y) * max(a.x, b.x) / f;  // metres between the two fluid texels
  if (span > u_fill_world || abs(a.x - b.x) > mu + span) return 0.0;
  float z = mix(a.x, b.x, a.y / (a.y + b.y));
  return window_depth(z) < texelFetch(u_scene_depth_w, p, 0).r ? with_drop_flag(z, false) : 0.0;
}

// Depth of the tangent reference i texels from the centre (depth c, inverse depth slope k); 0
// where the tangent plane is behind the camera there (no depth of this surface can lie there).
float tangent_depth(float c, float k, int i) {
  float inv = 1.0 / c + k * float(i);
  return inv > 0.0 ? 1.0 / inv : 0.0;
}

// The surface's inverse depth slope per texel at p (depth c) along dir, measured to the farthest
// surface texel within b on each side (a baseline of the kernel's scale, over which the splats'
// bumps average out more than between neighbours): the ends' depths z and signed distances at
// (0: no surface on that side), and the two one-sided slopes k.
struct Slope {
  vec2 z, at, k;
};

Slope slope_ends(ivec2 p, ivec2 dir, float c, int b) {
  ivec2 size = textureSize(u_src, 0);
  Slope e;
  e.z = vec2(0.0), e.at = vec2(0.0), e.k = vec2(0.0);
  for (int side = 0; side < 2; ++side) {
    int towards = 2 * side - 1;
    for (int i = b; i >= 1; --i) {
      ivec2 q = p + towards * i * dir;
      if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, size))) continue;
      float s = texelFetch(u_src, q, 0).r;
      if (s <= 0.0 || is_drop(s)) continue;
      e.z[side] = s, e.at[side] = float(towards * i), e.k[side] = (1.0 / s - 1.0 / c) / float(towards * i);
      break;
    }
  }
  return e;
}

// The one-sided slope of smaller magnitude: where one side crosses a discontinuity, the other
// is on this surface (as the normals choose, ssfr_normal.glsl).
float gentler(Slope e) {
  if (e.at.x == 0.0 || e.at.y == 0.0) return e.k.x + e.k.y;  // one side (or none) has surface
  return abs(e.k.x) < abs(e.k.y) ? e.k.x : e.k.y;
}

// The slope for the range reference: where both ends lie on one surface (each within mu of the
// line through the centre and the other end), the central difference, exact for a plane;
// otherwise the gentler one-sided slope.
float reference_slope(Slope e, float c, float mu) {
  if (e.at.x == 0.0 || e.at.y == 0.0) return e.k.x + e.k.y;
  if (abs(tangent_depth(c, e.k.x, int(e.at.y)) - e.z.y) <= mu && abs(tangent_depth(c, e.k.y, int(e.at.x)) - e.z.x) <= mu)
    return (1.0 / e.z.y - 1.0 / e.z.x) / (e.at.y - e.at.x);
  return gentler(e);
}

// The tangent plane at p (depth c) from the gentler inverse depth slopes along and across the
// pass (dz = -z^2 d(1/z)): the cosine of the angle between the view ray and its normal, and the
// distance on the plane per texel step along and across the pass (metres).
// The range in depth: mu is a tolerance on the surface's height (its bumps are the particles',
// and a sample further from the tangent than that is another surface); a height offset along the
// normal shows in depth divided by cos theta. Seen face-on that is mu; on the puddle seen from
// 15 cm above at 0.6 m it is 4 mu: there the splats' bumps are 4 times as deep in depth as in
// height, and a range of mu cuts into them. 1 / cos theta is capped at kMaxRangeGrowth (83
// degrees): steeper is a silhouette, not a surface seen at a grazing angle. A sample further than
// that in front (another surface) is still clamped to mu in front of the reference, not to the
// grown range: a nearer surface pulls this one forward by at most Truong & Yuksel's mu in depth
// per pass, as face-on (clamped to the grown range, a drop in front of the grazing puddle pulled
// the puddle beside it 4 times as far, most of the way to the drop).
// The half-width: u_world_radius on the surface, not in the image plane. Projected without the
// tilt, the window along the puddle's rows spans 4 times the surface it spans across them (and
// the pixel cap u_max_px cuts the one across first): the depth, smoothed far more in one direction
// than the other, keeps the particles' bumps as streaks along the less smoothed one. Both passes
// take the same radius on the surface: the world radius, or less where the pixel cap would cut
// either axis's.
const float kMaxRangeGrowth = 8.0;
void tangent_plane(ivec2 p, float c, float k_along, float k_across, out float cos_t, out vec2 step) {
  vec3 ray = pixel_ray(texel_pixel(p));
  float za = -c * c * k_along, zc = -c * c * k_across;  // depth per texel along and across the pass
  vec2 g = u_dir.x != 0 ? vec2(za, zc) : vec2(zc, za);   // along window x, y
  vec3 tx = g.x * ray + vec3(c / u_K.x, 0.0, 0.0), ty = g.y * ray + vec3(0.0, -c / u_K.y, 0.0);  // window y runs up
  vec3 n = cross(tx, ty);
  cos_t = abs(dot(n, ray)) / max(length(n) * length(ray), 1e-30);
  step = u_dir.x != 0 ? vec2(length(tx), length(ty)) : vec2(length(ty), length(tx));
}

float filter_at(ivec2 p) {
  float c = texelFetch(u_src, p, 0).r;
  if (u_skip_empty && c <= 0.0) return u_fill_world > 0.0 ? fill_at(p, 3.0 * u_range_sigma) : 0.0;
  if (u_skip_empty && is_drop(c)) return c;  // a lone drop keeps its sphere (and its flag)
  float f = u_dir.x != 0 ? u_K.x : u_K.y;
  float z_width = c;
  if (!u_skip_empty) {
    vec2 at_full = (vec2(p) + 0.5) / vec2(textureSize(u_src, 0));
    z_width = texelFetch(u_width_depth, ivec2(at_full * vec2(textureSize(u_width_depth, 0))), 0).r;
    if (z_width <= 0.0) return c;
  }
  int r = int(min(float(u_max_px), u_world_radius * f / z_width));
  if (r < 1) return c;
  float mu = 3.0 * u_range_sigma, clamp_mu = mu;
  bool ranged = u_range_sigma > 0.0;
  float k = 0.0;
  if (ranged) {
    int b = max(1, r / 2);
    Slope along = slope_ends(p, u_dir, c, b);
    float cos_t;
    vec2 step;
    tangent_plane(p, c, gentler(along), gentler(slope_ends(p, u_dir.yx, c, b)), cos_t, step);
    mu /= max(cos_t, 1.0 / kMaxRangeGrowth);
    k = reference_slope(along, c, mu);
    float radius = min(u_world_radius, float(u_max_px) * min(step.x, step.y));
    r = int(radius / step.x);
    if (r < 1) return with_drop_flag(c, false);
  }
  int stride = (r + u_max_taps - 1) / u_max_taps;
  float rr = float(r + 1);  // the biweight is zero at +-(r + 1): the outermost taps still count
  ivec2 hi = textureSize(u_src, 0) - 1;
  int at = u_dir.x != 0 ? p.x : p.y;
  int lo = at - r;  // the first lattice point at or after lo (integer division truncates toward 0)
  int first = (lo >= 0 ? (lo + stride - 1) / stride : -((-lo) / stride)) * stride - at;
  float sum = 0.0, wsum = 0.0;
  for (int i = first; i <= r; i += stride) {
    float s = texelFetch(u_src, clamp(p + i * u_dir, ivec2(0), hi), 0).r;
    if (u_skip_empty && (s <= 0.0 || is_drop(s))) continue;
    float x = float(i) / rr;
    float w = (1.0 - x * x) * (1.0 - x * x);
    if (ranged) {
      float ref = tangent_depth(c, k, i);
      if (ref <= 0.0) continue;
      float e = s - ref;  // the sample's difference from the tangent reference
      if (u_narrow_range) {
        if (e > mu) continue;
        if (e < -mu) e = -clamp_mu;
      } else {
        float dz = 3.0 * e / mu;  // the range sigma, grown as mu
        w *= exp(-0.5 * dz * dz);
      }
      s = 1.0 / max(ref + e, 0.5 * ref) - 1.0 / ref;  // as a difference of inverse depths
    }
    sum += s * w;
    wsum += w;
  }
  if (wsum <= 0.0) return c;  // no tap on fluid (a sliver between lattice points): as it was
  float v = sum / wsum;
  if (ranged) v = 1.0 / c + v > 0.0 ? 1.0 / (1.0 / c + v) : c;
  return u_skip_empty ? with_drop_flag(v, false) : v;
}
