// Shadow pass 3: particle spheres (the fluid) into the map, as a compute splat like the fluid's
// depth and thickness (ssfr_depth_splat.comp, ssfr_thickness_splat.comp) but orthographic along
// the light: each particle takes the texels of its disc at the coarser level splat_level()
// (shadow.glsl), keeps the nearest front depth per texel by an atomic minimum on the float's bits
// (depths below z0 are positive, and positive floats order like their bits) and adds its chord
// to the texel's path in fluid (fixed point, as the camera's thickness splat). Needs
// camera.glsl, sphere_hit.glsl (u_radius: the sphere radius) and splat.glsl (particle buffers).
layout(r32ui, binding = 0) uniform uimage2D u_shadow_bits;   // 0xffffffff = no particle
layout(r32ui, binding = 1) uniform uimage2D u_shadow_thick;  // path in fluid, fixed point; 0 = none
uniform float u_thickness_scale;  // inverse volume fraction of the enlarged spheres (ssfr_thickness.frag)
uniform float u_fixed_per_metre;

void main() {
  uint i = particle_index();
  if (i >= u_count || (b_phase[i] & u_phase_mask) == 0u) return;
  LightMap m = light_map();
  if (!m.valid) return;
  int k = splat_level(m, u_radius);
  float t = m.texel * float(1 << k);  // metres per texel of this level
  int size = int(u_shadow_size) >> k;
  vec3 q = u_light_R * vec3(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u]);
  vec2 a = (q.xy - m.lo) / t;  // centre in texels of this level
  float rt = u_radius / t;
  ivec2 lo = max(ivec2(ceil(a - rt - 0.5)), ivec2(0));
  ivec2 hi = min(ivec2(floor(a + rt - 0.5)), ivec2(size - 1));
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      vec2 d = (vec2(x, y) + 0.5 - a) * t;
      float h2 = u_radius * u_radius - dot(d, d);
      if (h2 <= 0.0) continue;
      float h = sqrt(h2);
      ivec2 p = ivec2(x, y);
      imageAtomicAdd(u_shadow_thick, p, uint(2.0 * h * u_thickness_scale * u_fixed_per_metre + 0.5));
      uint bits = floatBitsToUint(max(q.z - h - m.z0, 0.0));
      if (imageLoad(u_shadow_bits, p).r <= bits) continue;  // see ssfr_depth_splat.comp
      imageAtomicMin(u_shadow_bits, p, bits);
    }
}
