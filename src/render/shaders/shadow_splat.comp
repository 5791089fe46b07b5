// Shadow pass 3: particle spheres (the fluid) into the map, as a compute splat like the fluid's
// depth and thickness (ssfr_depth_splat.comp, ssfr_thickness_splat.comp) but orthographic along
// the light: each particle takes the texels of its disc at the coarser level splat_level()
// (shadow.glsl), keeps the nearest front depth per texel by an atomic minimum on the float's bits
// (depths below z0 are positive, and positive floats order like their bits) and adds its chord
// to the texel's path in fluid (fixed point, as the camera's thickness splat). With anisotropic
// kernels (u_aniso) each particle is its ellipsoid, as in the camera's splats, so a spread layer
// casts one continuous shadow instead of a disc per particle. Needs camera.glsl, sphere_hit.glsl
// (u_radius: the sphere radius) and splat.glsl (particle buffers, ellipsoids).
layout(r32ui, binding = 0) uniform uimage2D u_shadow_bits;   // 0xffffffff = no particle
layout(r32ui, binding = 1) uniform uimage2D u_shadow_thick;  // path in fluid, fixed point; 0 = none
uniform float u_thickness_scale;  // inverse volume fraction of the enlarged spheres (ssfr_thickness.frag)
uniform float u_fixed_per_metre;

void main() {
  uint i = particle_index();
  if (i >= u_count || (b_phase[i] & u_phase_mask) == 0u) return;
  LightMap m = light_map();
  if (!m.valid) return;
  int k = splat_level(m, u_radius);  // one level for all: the receivers read it (shadow.glsl)
  float t = m.texel * float(1 << k);  // metres per texel of this level
  int size = int(u_shadow_size) >> k;
  // Centre and bounding radius in the light's frame; for an ellipsoid its matrix there too,
  // L M L^T with L = u_light_R (world -> light).
  vec3 q;
  float r = u_radius;
  mat3 M = mat3(1.0);
  if (u_aniso) {
    vec4 e0 = b_ell[3u * i], e1 = b_ell[3u * i + 1u], e2 = b_ell[3u * i + 2u];
    q = u_light_R * e0.xyz;
    r = e0.w;
    M = u_light_R * mat3(e1.x, e1.y, e1.z, e1.y, e1.w, e2.x, e1.z, e2.x, e2.y) * transpose(u_light_R);
  } else {
    q = u_light_R * vec3(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u]);
  }
  vec2 a = (q.xy - m.lo) / t;  // centre in texels of this level
  float rt = r / t;
  ivec2 lo = max(ivec2(ceil(a - rt - 0.5)), ivec2(0));
  ivec2 hi = min(ivec2(floor(a + rt - 0.5)), ivec2(size - 1));
  for (int y = lo.y; y <= hi.y; ++y)
    for (int x = lo.x; x <= hi.x; ++x) {
      vec2 d = (vec2(x, y) + 0.5 - a) * t;
      // The texel's ray along the light, q + (d, s): the half chord h and the middle s0 of the
      // ellipsoid's (o^T M o = 1 for o = (d, s): M_zz s^2 + 2 B s + C - 1 = 0) or the sphere's.
      float h, s0 = 0.0;
      if (u_aniso) {
        float B = M[0][2] * d.x + M[1][2] * d.y;
        float C = M[0][0] * d.x * d.x + 2.0 * M[1][0] * d.x * d.y + M[1][1] * d.y * d.y;
        float disc = B * B - M[2][2] * (C - 1.0);
        if (disc <= 0.0) continue;
        h = sqrt(disc) / M[2][2];
        s0 = -B / M[2][2];
      } else {
        float h2 = u_radius * u_radius - dot(d, d);
        if (h2 <= 0.0) continue;
        h = sqrt(h2);
      }
      ivec2 p = ivec2(x, y);
      imageAtomicAdd(u_shadow_thick, p, uint(2.0 * h * u_thickness_scale * u_fixed_per_metre + 0.5));
      uint bits = floatBitsToUint(max(q.z + s0 - h - m.z0, 0.0));
      if (imageLoad(u_shadow_bits, p).r <= bits) continue;  // see ssfr_depth_splat.comp
      imageAtomicMin(u_shadow_bits, p, bits);
    }
}
