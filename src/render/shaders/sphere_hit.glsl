// Exact ray-sphere intersection for a point sprite's fragment (needs camera.glsl).
uniform float u_radius;
flat in vec3 v_centre;

// Eye depths where this pixel's ray enters and leaves the sphere; false if it misses.
bool hit_sphere(out float z_in, out float z_out) {
  vec3 d = pixel_ray(frag_pixel());
  float a = dot(d, d), b = dot(d, v_centre), c = dot(v_centre, v_centre) - u_radius * u_radius;
  float disc = b * b - a * c;
  if (disc < 0.0) return false;
  float s = sqrt(disc);
  z_in = (b - s) / a;  // d.z = 1, so the ray parameter is the eye depth
  z_out = (b + s) / a;
  return z_in > u_near_far.x;
}
