// Shadow pass 3: particle spheres (the fluid) into the map, as a compute splat like the fluid's
// depth (ssfr_depth_splat.comp) but orthographic along the light: each particle takes the texels
// of its disc at the coarser level splat_level() (shadow.glsl) and keeps the nearest front
// depth per texel by an atomic minimum on the float's bits (depths below z0 are positive, and
// positive floats order like their bits). Needs camera.glsl, sphere_hit.glsl (u_radius: the
// sphere radius) and splat.glsl (particle buffers) before it.
layout(r32ui, binding = 0) uniform uimage2D u_shadow_bits;  // 0xffffffff = no particle

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
      uint bits = floatBitsToUint(max(q.z - sqrt(h2) - m.z0, 0.0));
      ivec2 p = ivec2(x, y);
      if (imageLoad(u_shadow_bits, p).r <= bits) continue;  // see ssfr_depth_splat.comp
      imageAtomicMin(u_shadow_bits, p, bits);
    }
}
