// Cloth: one triangle mesh drawn straight from the particle buffer (no copy of the positions):
// the element indices are particle ids, so gl_VertexID is the particle, and its position comes
// from the buffer texture over the renderer's particle positions (filled by the host upload or by
// CUDA interop). The smooth normal is computed here, per frame, as the area-weighted sum of the
// normals of the triangles around the vertex (the same sum as render::vertex_normals). With
// shadow_caster.glsl first (and shadow.glsl) the sheet goes into the shadow map instead.
uniform samplerBuffer u_pos;        // particle positions, world (RGB32F)
uniform isamplerBuffer u_ring_off;  // per cloth vertex (id - u_first): first entry in u_ring; +1: end
uniform isamplerBuffer u_ring;      // (j, k) for each triangle (i, j, k) around vertex i, winding kept
uniform int u_first;                // lowest particle id of the sheets
uniform samplerBuffer u_uv;         // per cloth vertex (id - u_first): its place in its sheet's grid, cells
uniform mat4 u_view, u_proj;
uniform vec3 u_tint;

out vec3 v_normal;
out vec3 v_world;
out vec3 v_world_normal;
out vec3 v_color;
out vec2 v_uv;
out vec3 v_eye;

void main() {
  int i = gl_VertexID;
  vec3 p = texelFetch(u_pos, i).xyz;
  int a = texelFetch(u_ring_off, i - u_first).r, b = texelFetch(u_ring_off, i - u_first + 1).r;
  vec3 n = vec3(0.0);
  for (int t = a; t < b; ++t) {
    ivec2 jk = texelFetch(u_ring, t).xy;
    n += cross(texelFetch(u_pos, jk.x).xyz - p, texelFetch(u_pos, jk.y).xyz - p);  // |n| = twice the area
  }
  v_normal = mat3(u_view) * n;  // normalised per fragment (mesh.frag)
  v_world = p;
  v_world_normal = n;
  v_color = u_tint;
  v_uv = texelFetch(u_uv, i - u_first).xy;
#ifdef SEAMLESS_SHADOW_CASTER
  v_eye = p;
  gl_Position = light_clip(p);
#else
  vec4 e = u_view * vec4(p, 1.0);
  v_eye = e.xyz;
  gl_Position = u_proj * e;
#endif
}
