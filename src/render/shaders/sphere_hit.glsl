// Exact ray-sphere intersection (needs camera.glsl), shared by the sprite fragment shaders and the
// compute splats (ssfr_*_splat.comp), so that both paths compute the same depths bit for bit.
uniform float u_radius;

// Eye depths where the ray z * d (d from pixel_ray, d.z = 1) enters and leaves the sphere of
// radius u_radius about eye-space centre c; false if it misses or enters before the near plane.
bool ray_sphere(vec3 d, vec3 c, out float z_in, out float z_out) {
  float a = dot(d, d), b = dot(d, c), cc = dot(c, c) - u_radius * u_radius;
  float disc = b * b - a * cc;
  if (disc < 0.0) return false;
  float s = sqrt(disc);
  z_in = (b - s) / a;  // d.z = 1, so the ray parameter is the eye depth
  z_out = (b + s) / a;
  return z_in > u_near_far.x;
}

// The same for the ellipsoid (x - c)^T M (x - c) <= 1 (eye space; anisotropic kernels): the
// quadratic (d^T M d) z^2 - 2 (d^T M c) z + c^T M c - 1 = 0.
bool ray_quadric(vec3 d, vec3 c, mat3 M, out float z_in, out float z_out) {
  vec3 Md = M * d;
  float a = dot(d, Md), b = dot(c, Md), cc = dot(c, M * c) - 1.0;
  float disc = b * b - a * cc;
  if (disc < 0.0) return false;
  float s = sqrt(disc);
  z_in = (b - s) / a;
  z_out = (b + s) / a;
  return z_in > u_near_far.x;
}

#ifndef SEAMLESS_COMPUTE
flat in vec3 v_centre;

// The same for this fragment's pixel and the sprite's sphere.
bool hit_sphere(out float z_in, out float z_out) { return ray_sphere(pixel_ray(frag_pixel()), v_centre, z_in, z_out); }
#endif
