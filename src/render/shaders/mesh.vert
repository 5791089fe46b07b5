// Triangle meshes: scene mesh, rigid boxes, cloth. Normals and lighting in eye space.
layout(location = 0) in vec3 a_pos;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec3 a_color;

uniform mat4 u_model, u_view, u_proj;
uniform vec3 u_tint;
uniform bool u_vertex_color;

out vec3 v_normal;
out vec3 v_color;

void main() {
  vec4 pe = u_view * (u_model * vec4(a_pos, 1.0));
  // Model and view are rigid (plus a per-axis scale for the unit box, whose normals are axes).
  v_normal = mat3(u_view) * mat3(u_model) * a_normal;
  v_color = u_vertex_color ? a_color : u_tint;
  gl_Position = u_proj * pe;
}
