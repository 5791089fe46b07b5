// SSFR thickness as a compute splat (van der Laan et al. 2009, section 4.3; same result as
// sphere.vert + ssfr_thickness.frag up to the fixed-point rounding): the length of each pixel's
// ray inside each sphere, cut at the scene, summed by atomic adds in fixed point (float image
// atomics are an NVIDIA extension, not core GL nor Mesa). Runs at the thickness resolution: the
// camera uniforms (u_K, u_size) are those of the reduced image.
layout(r32ui, binding = 0) uniform uimage2D u_thick_fixed;
uniform float u_thickness_scale;  // inverse volume fraction (ssfr_thickness.frag)
uniform float u_fixed_per_metre;  // fixed-point units per metre of path (renderer_fluid.cpp)

void main() {
  Splat s;
  ivec2 lo, hi;
  if (!splat_shape(particle_index(), s) || !splat_rect(s.c, s.r, lo, hi)) return;
  for (int v = lo.y; v <= hi.y; ++v)
    for (int u = lo.x; u <= hi.x; ++u) {
      float z_in, z_out;
      vec3 d = pixel_ray(vec2(u, v));
      if (!ray_splat(d, s, z_in, z_out)) continue;
      ivec2 t = window_texel(ivec2(u, v));
      // Same sample of the full-size scene depth as the fragment shader's gl_FragCoord / u_size.
      float z_scene = eye_depth(texture(u_scene_depth, (vec2(t) + 0.5) / u_size).r);
      float len = (min(z_out, z_scene) - z_in) * length(d);
      if (len <= 0.0) continue;
      imageAtomicAdd(u_thick_fixed, t, uint(len * u_thickness_scale * u_fixed_per_metre + 0.5));
    }
}
