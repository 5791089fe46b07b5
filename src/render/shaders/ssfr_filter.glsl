// SSFR smoothing (van der Laan et al. 2009, section 4.2), one axis per pass: run along x, then
// along y. Depth: the half-width is a world size projected at this pixel's depth, and empty
// pixels neither change nor contribute. Two edge-preserving modes:
//  - bilateral (the paper's cheaper alternative to curvature flow): Gaussian range weight.
//  - narrow range (Truong & Yuksel 2018, "A Narrow-Range Filter for Screen-Space Fluid
//    Rendering", section 3): samples further than the range mu behind the centre belong to
//    another surface and are left out; samples further than mu in front are clamped to
//    z - mu, so that a nearer surface cannot pull this one forward, yet its edge still smooths.
//    mu = 3 range sigmas (where the bilateral weight has fallen to 1%).
// Thickness: a plain Gaussian of fixed pixel width (u_range_sigma <= 0, u_skip_empty false).
// Kernels wider than u_max_taps per side sample every k-th pixel (same Gaussian in pixels).
// filter_at() is the pass at one texel; ssfr_filter.frag and ssfr_filter.comp run it.
uniform sampler2D u_src;
uniform ivec2 u_dir;            // (1, 0) or (0, 1)
uniform float u_world_radius;   // metres
uniform int u_max_px;
uniform int u_max_taps;
uniform float u_range_sigma;    // metres; <= 0 disables the range weight
uniform bool u_skip_empty;
uniform bool u_narrow_range;

float filter_at(ivec2 p) {
  float c = texelFetch(u_src, p, 0).r;
  if (u_skip_empty && c <= 0.0) return 0.0;
  float f = u_dir.x != 0 ? u_K.x : u_K.y;
  int r = u_skip_empty ? int(min(float(u_max_px), u_world_radius * f / c)) : u_max_px;
  if (r < 1) return c;
  int stride = (r + u_max_taps - 1) / u_max_taps;
  float inv2s2 = 2.0 / float(r * r);  // spatial sigma = r / 2
  float mu = 3.0 * u_range_sigma;
  ivec2 hi = textureSize(u_src, 0) - 1;
  float sum = 0.0, wsum = 0.0;
  for (int i = -(r / stride) * stride; i <= r; i += stride) {  // multiples of stride: the centre is one
    float s = texelFetch(u_src, clamp(p + i * u_dir, ivec2(0), hi), 0).r;
    if (u_skip_empty && s <= 0.0) continue;
    float w = exp(-float(i * i) * inv2s2);
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
  return sum / wsum;
}
