// SSFR normals (van der Laan et al. 2009, section 4.2): eye-space positions from the smoothed
// depth, differences to the neighbours along x and y, taking on each axis the side with the
// smaller depth change so that silhouettes do not bend the normal. A lone drop (splat.glsl) and
// the surface are separate bodies: a drop texel's neighbours count only if they are the drop's
// (its sphere's normals), a surface texel's only if they are the surface's.
uniform sampler2D u_depth;

vec3 eye_pos(ivec2 t, float z) { return z * pixel_ray(vec2(float(t.x), u_size.y - 1.0 - float(t.y))); }

// Depth at texel t if it holds fluid of the same kind (drop or surface) as `drop`, else 0.
float same_body_depth(ivec2 t, bool drop) {
  ivec2 hi = textureSize(u_depth, 0) - 1;
  if (any(greaterThan(t, hi)) || any(lessThan(t, ivec2(0)))) return 0.0;
  float z = texelFetch(u_depth, t, 0).r;
  return z > 0.0 && is_drop(z) == drop ? z : 0.0;
}

// Difference along `step` (texel units), or the zero vector if neither neighbour holds fluid of
// the same body.
vec3 diff(ivec2 p, vec3 P, ivec2 step, bool drop) {
  ivec2 a = p + step, b = p - step;
  float za = same_body_depth(a, drop), zb = same_body_depth(b, drop);
  vec3 fa = za > 0.0 ? eye_pos(a, za) - P : vec3(0.0);
  vec3 fb = zb > 0.0 ? P - eye_pos(b, zb) : vec3(0.0);
  if (za <= 0.0) return fb;
  if (zb <= 0.0) return fa;
  return abs(fa.z) < abs(fb.z) ? fa : fb;
}

// The eye-space normal at texel p, w = 1 where there is fluid (ssfr_normal.frag / .comp run it).
vec4 normal_at(ivec2 p) {
  float z = texelFetch(u_depth, p, 0).r;
  if (z <= 0.0) return vec4(0.0);
  vec3 P = eye_pos(p, z);
  bool drop = is_drop(z);
  vec3 dx = diff(p, P, ivec2(1, 0), drop), dy = diff(p, P, ivec2(0, 1), drop);
  vec3 n = cross(dx, dy);
  n = dot(n, n) > 0.0 ? normalize(n) : vec3(0.0, 0.0, -1.0);  // a lone pixel faces the camera
  if (dot(n, P) > 0.0) n = -n;                               // towards the viewer
  return vec4(n, 1.0);
}
