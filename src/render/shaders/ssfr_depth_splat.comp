// SSFR pass 1 as a compute splat (van der Laan et al. 2009, section 4.1; same result as
// sphere.vert + ssfr_depth.frag): each particle intersects the rays of its sprite's pixels with
// its sphere and keeps the nearest entry depth per pixel by an atomic minimum on the float's
// bits (positive IEEE floats order like their bit patterns as unsigned integers).
//
// Occluders first (render.fluid_occluders, with the anisotropic kernels): the minimum does not
// depend on the order of the particles, so they may be splatted in two passes. Pass 1 splats the
// particles at the fluid's surface (the occluder list of ssfr_occluders.comp); ssfr_depth_tiles.comp
// then takes the largest depth of each 4 x 4 pixel tile. Pass 2 splats the others, but first
// bounds the particle's entry depth at every pixel of its rect from below (its bounding sphere's
// front, less the entry depth's rounding error): if every tile its rect touches already holds
// only smaller depths, none of its atomics could lower a pixel, and it skips them all. The image
// is the same bit for bit as one pass over every particle; inside a body of water most particles
// take the skip. In every pass a pixel whose depth is already in front of the bounding sphere
// along its ray skips the intersection.
layout(r32ui, binding = 0) uniform uimage2D u_depth_bits;  // 0xffffffff = no fluid (resolve: 0)
layout(r32ui, binding = 1) uniform readonly uimage2D u_depth_tiles;  // pass 2: ssfr_depth_tiles.comp's
// The occluders (ssfr_occluders.comp): how many, how many of the others pass 2 skipped, which.
layout(std430, binding = 3) buffer Occluders {
  uint b_occluder_count;
  uint b_skipped;
  uint b_occluder[];
};
uniform int u_pass;  // 0: every particle; 1: the occluders; 2: the others (skipped when hidden)
uniform float u_occluder_offset;  // ssfr_occluders.comp's

shared uint s_skipped;

// How far the float entry depth of a splat can fall below the exact one: its rounding error is
// dominated by the cancellation in the quadric's c^T M c - 1 (c^T M c is up to 16 (c.z / r)^2 for
// the flattest ellipsoid, so its ulps are ~1e-6 c.z^2 / r^2, and the entry depth moves by r / 2 per
// unit of it at the centre ray); four times that, plus a quarter radius and a relative 1e-6 for
// the other terms.
float depth_margin(Splat s) { return 0.25 * s.r + 4e-6 * s.c.z * s.c.z / s.r + 1e-6 * s.c.z; }

// The depth bits below which a pixel cannot be lowered by a splat whose entry depth there is at
// least z (z already less the margin): 0 for none.
uint lower_bound_bits(float z) { return z > 0.0 ? floatBitsToUint(z) & ~3u : 0u; }  // the drop tag: two bits

// Whether the splat can lower no pixel of the image (pass 2): its entry depth at any pixel is at
// least its bounding sphere's front c.z - r, and every tile of 4 x 4 pixels its rect touches
// already holds only smaller depths.
bool hidden(Splat s, ivec2 lo, ivec2 hi) {
  // Image rows run down, window rows (the images') up.
  ivec2 t_lo = ivec2(lo.x, int(u_size.y) - 1 - hi.y) >> 2, t_hi = ivec2(hi.x, int(u_size.y) - 1 - lo.y) >> 2;
  ivec2 n = t_hi - t_lo + 1;
  if (n.x * n.y > 36) return false;  // a large splat: not worth the loads
  uint bound = lower_bound_bits(s.c.z - s.r - depth_margin(s));
  for (int y = t_lo.y; y <= t_hi.y; ++y)
    for (int x = t_lo.x; x <= t_hi.x; ++x)
      if (imageLoad(u_depth_tiles, ivec2(x, y)).r >= bound) return false;
  return true;
}

void splat(uint i) {
  if (u_pass == 2 && b_ell[3u * i + 2u].w >= u_occluder_offset) return;  // an occluder: pass 1 splatted it
  Splat s;
  ivec2 lo, hi;
  if (!splat_shape(i, s) || !splat_rect(s.c, s.r, lo, hi)) return;
  if (u_pass == 2 && hidden(s, lo, hi)) {
    atomicAdd(s_skipped, 1u);
    return;
  }
  float margin = depth_margin(s);
  for (int v = lo.y; v <= hi.y; ++v)
    for (int u = lo.x; u <= hi.x; ++u) {
      vec3 d = pixel_ray(vec2(u, v));
      ivec2 t = window_texel(ivec2(u, v));
      // Depths only decrease, so a stale plain read can only let through an atomic that was not
      // needed; skipping on it is always right. Skipped first without the intersection: the
      // entry depth along this ray is at least that into the bounding sphere, which is at least
      // c.d / |d|^2 - r / |d| (d.z = 1: the depth is the distance over |d|).
      uint current = imageLoad(u_depth_bits, t).r;
      float inv = 1.0 / dot(d, d);
      if (current < lower_bound_bits(dot(s.c, d) * inv - s.r * sqrt(inv) - margin)) continue;
      float z_in, z_out;
      if (!ray_splat(d, s, z_in, z_out)) continue;
      // Hidden by the scene: the raster path's depth test against the copied scene depth (window
      // depth, GL_LESS), done on the same values.
      if (window_depth(z_in) >= texelFetch(u_scene_depth, t, 0).r) continue;
      uint bits = floatBitsToUint(with_drop_tag(z_in, s.drop, s.flat_drop));
      if (current <= bits) continue;  // saves most atomics inside the fluid
      imageAtomicMin(u_depth_bits, t, bits);
    }
}

void main() {
  if (gl_LocalInvocationIndex == 0u) s_skipped = 0u;
  barrier();
  uint i = particle_index();
  if (u_pass != 1) splat(i);
  else if (i < b_occluder_count) splat(b_occluder[i]);
  barrier();
  if (gl_LocalInvocationIndex == 0u && s_skipped > 0u) atomicAdd(b_skipped, s_skipped);
}
