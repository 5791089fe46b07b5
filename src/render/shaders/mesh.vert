// Triangle meshes: scene mesh, rigid boxes, cloth. Normals and lighting in eye space; world
// position and normal for the shadow lookup. With shadow_caster.glsl first (and shadow.glsl) the
// same vertices go into the shadow map instead (renderer_shadow.cpp).
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_color;

uniform mat4 u_model, u_view, u_proj;
uniform vec3 u_tint;
uniform bool u_vertex_color;

out vec3 v_normal;
out vec3 v_world;
out vec3 v_world_normal;
out vec3 v_color;

void main() {
  vec4 pw = u_model * vec4(a_pos, 1.0);
  // Model and view are rigid (plus a per-axis scale for the unit box, whose normals are axes).
  v_world_normal = mat3(u_model) * a_normal;
  v_normal = mat3(u_view) * v_world_normal;
  v_world = pw.xyz;
  v_color = u_vertex_color ? a_color : u_tint;
#ifdef SEAMLESS_SHADOW_CASTER
  gl_Position = light_clip(pw.xyz);
#else
  gl_Position = u_proj * (u_view * pw);
#endif
}
