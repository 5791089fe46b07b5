// SSFR pass 1 as a compute splat (van der Laan et al. 2009, section 4.1; same result as
// sphere.vert + ssfr_depth.frag): each particle intersects the rays of its sprite's pixels with
// its sphere and keeps the nearest entry depth per pixel by an atomic minimum on the float's
// bits (positive IEEE floats order like their bit patterns as unsigned integers).
layout(r32ui, binding = 0) uniform uimage2D u_depth_bits;  // 0xffffffff = no fluid (resolve: 0)

void main() {
  Splat s;
  ivec2 lo, hi;
  if (!splat_shape(particle_index(), s) || !splat_rect(s.c, s.r, lo, hi)) return;
  for (int v = lo.y; v <= hi.y; ++v)
    for (int u = lo.x; u <= hi.x; ++u) {
      float z_in, z_out;
      if (!ray_splat(pixel_ray(vec2(u, v)), s, z_in, z_out)) continue;
      ivec2 t = window_texel(ivec2(u, v));
      // Hidden by the scene: the raster path's depth test against the copied scene depth (window
      // depth, GL_LESS), done on the same values.
      if (window_depth(z_in) >= texelFetch(u_scene_depth, t, 0).r) continue;
      uint bits = floatBitsToUint(with_drop_tag(z_in, s.drop, s.flat_drop));
      // Depths only decrease, so a stale plain read can only let an atomic through that was not
      // needed; skipping on it is always right, and it saves most atomics inside the fluid.
      if (imageLoad(u_depth_bits, t).r <= bits) continue;
      imageAtomicMin(u_depth_bits, t, bits);
    }
}
