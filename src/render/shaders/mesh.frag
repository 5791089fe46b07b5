in vec3 v_normal;
in vec3 v_world;
in vec3 v_world_normal;
in vec3 v_color;

uniform vec3 u_light;     // unit direction towards the light, eye space
uniform float u_ambient;
uniform bool u_lit;
uniform bool u_two_sided;  // cloth; closed meshes and the scan keep their outward normals

layout(location = 0) out vec4 o_color;

void main() {
  vec3 n = normalize(v_normal);
  vec3 nw = normalize(v_world_normal);
  // Two-sided surfaces (cloth) are one mesh: the normal is turned towards the side being seen,
  // so the back face is lit like the front instead of drawing a second, offset copy.
  if (u_two_sided && !gl_FrontFacing) n = -n, nw = -nw;
  vec3 light = shadow_light(v_world, nw, gl_FragCoord.xy);
  if (u_lit) {
    // The light's share is its diffuse term; a shadow takes away (part of) that share only.
    vec3 diffuse = max(dot(n, u_light), 0.0) * light;
    o_color = vec4(v_color * (u_ambient + (1.0 - u_ambient) * diffuse), 1.0);
  } else {
    o_color = vec4(shadowed_srgb(v_color, light, 0.0), 1.0);  // the scan's colours hold its light
  }
}
