// Debug view: every particle as a lit sphere, coloured by its phase.
flat in uint v_phase;
uniform vec3 u_light;
uniform float u_ambient;

layout(location = 0) out vec4 o_color;
#ifdef GL_ARB_conservative_depth
layout(depth_greater) out float gl_FragDepth;  // the sphere lies behind its sprite (sphere.vert)
#endif

vec3 phase_color(uint ph) {
  if ((ph & (1u << 24)) != 0u) return vec3(0.2, 0.45, 0.95);  // fluid
  if ((ph & (1u << 25)) != 0u) return vec3(0.85, 0.3, 0.2);   // rigid
  if ((ph & (1u << 26)) != 0u) return vec3(0.9, 0.75, 0.3);   // cloth
  return vec3(0.8);
}

void main() {
  float z_in, z_out;
  if (!hit_sphere(z_in, z_out)) discard;
  vec3 p = z_in * pixel_ray(frag_pixel());
  vec3 n = normalize(p - v_centre);
  float diffuse = max(dot(n, u_light), 0.0);
  o_color = vec4(phase_color(v_phase) * (u_ambient + (1.0 - u_ambient) * diffuse), 1.0);
  gl_FragDepth = window_depth(z_in);
}
