// Particles as point sprites large enough to cover their sphere; the fragment shaders intersect
// the pixel's ray with the sphere exactly (sphere_hit.glsl), so the sprite only bounds it.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in uint a_phase;

uniform mat4 u_view, u_proj;
uniform float u_radius;
uniform float u_fmax;        // max(fx, fy), pixels
uniform uint u_phase_mask;   // draw particles with any of these phase flags; 0 = all
uniform float u_max_point_size;  // pixels (render.max_point_size)

flat out vec3 v_centre;      // eye space
flat out uint v_phase;

void main() {
  vec4 pe = u_view * vec4(a_pos, 1.0);
  v_centre = pe.xyz;
  v_phase = a_phase;
  bool keep = u_phase_mask == 0u || (a_phase & u_phase_mask) != 0u;
  if (!keep || pe.z <= u_radius) {
    gl_Position = vec4(0.0, 0.0, 2.0, 1.0);  // beyond the far plane: the point is clipped
    gl_PointSize = 1.0;
    return;
  }
  // The sprite sits at the sphere's nearest depth, pe.z - r, on the ray through the centre (same
  // projected centre): every fragment's sphere depth is then behind the sprite's, which the
  // fragment shaders declare (conservative depth), so the depth test can run before them.
  gl_Position = u_proj * vec4(pe.xyz * ((pe.z - u_radius) / pe.z), 1.0);
  // Half-width of the sphere's image, bounded by r f / (z - r) (the silhouette's extent at the
  // front depth), plus a pixel; cut at u_max_point_size so that a sphere next to the camera
  // cannot cover the screen with fragments.
  gl_PointSize = min(2.0 * u_radius * u_fmax / (pe.z - u_radius) + 2.0, u_max_point_size);
}
