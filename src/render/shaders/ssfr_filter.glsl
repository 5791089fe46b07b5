// SSFR smoothing (van der Laan et al. 2009, section 4.2), one axis per pass: run along x, then
// along y. Depth: the half-width is a world size projected at this pixel's depth, and empty
// pixels neither change nor contribute. Two edge-preserving modes:
//  - bilateral (the paper's cheaper alternative to curvature flow): Gaussian range weight.
//  - narrow range (Truong & Yuksel 2018, "A Narrow-Range Filter for Screen-Space Fluid
//    Rendering", section 3): samples further than the range mu behind the centre belong to
//    another surface and are left out; samples further than mu in front are clamped to
//    z - mu, so that a nearer surface cannot pull this one forward, yet its edge still smooths.
//    mu = 3 range sigmas (where the bilateral weight has fallen to 1%).
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
    if (s > 0.0) return vec2(s, float(i));
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
  return window_depth(z) < texelFetch(u_scene_depth_w, p, 0).r ? z : 0.0;
}

float filter_at(ivec2 p) {
  float c = texelFetch(u_src, p, 0).r;
  if (u_skip_empty && c <= 0.0) return u_fill_world > 0.0 ? fill_at(p, 3.0 * u_range_sigma) : 0.0;
  float f = u_dir.x != 0 ? u_K.x : u_K.y;
  float z_width = c;
  if (!u_skip_empty) {
    vec2 at_full = (vec2(p) + 0.5) / vec2(textureSize(u_src, 0));
    z_width = texelFetch(u_width_depth, ivec2(at_full * vec2(textureSize(u_width_depth, 0))), 0).r;
    if (z_width <= 0.0) return c;
  }
  int r = int(min(float(u_max_px), u_world_radius * f / z_width));
  if (r < 1) return c;
  int stride = (r + u_max_taps - 1) / u_max_taps;
  float rr = float(r + 1);  // the biweight is zero at +-(r + 1): the outermost taps still count
  float mu = 3.0 * u_range_sigma;
  ivec2 hi = textureSize(u_src, 0) - 1;
  int at = u_dir.x != 0 ? p.x : p.y;
  int lo = at - r;  // the first lattice point at or after lo (integer division truncates toward 0)
  int first = (lo >= 0 ? (lo + stride - 1) / stride : -((-lo) / stride)) * stride - at;
  float sum = 0.0, wsum = 0.0;
  for (int i = first; i <= r; i += stride) {
    float s = texelFetch(u_src, clamp(p + i * u_dir, ivec2(0), hi), 0).r;
    if (u_skip_empty && s <= 0.0) continue;
    float x = float(i) / rr;
    float w = (1.0 - x * x) * (1.0 - x * x);
    if (u_range_sigma > 0.0) {
      if (u_narrow_range) {
        if (s > c + mu) continue;
        s = max(s, c - mu);
      } else {
        float dz = (s - c) / u_range_sigma;
        w *= exp(-0.5 * dz * dz);
      }
    }
    sum += s * w;
    wsum += w;
  }
  return wsum > 0.0 ? sum / wsum : c;  // no tap on fluid (a sliver between lattice points): as it was
}
