// Cloth (cloth.vert's smooth per-vertex normals, two-sided), shaded in linear radiance (color.glsl)
// so that its folds show: the light's diffuse term (Lambert) and a fabric sheen (Estevez & Kulla
// 2017, "Production Friendly Microfacet Sheen BRDF": the "Charlie" distribution with Neubelt's
// visibility), both darkened by the virtual objects' shadows (shadow.glsl); the ambient part is
// weighted by how much the surface faces the light's half of the room (half of it facing away),
// so that folds in the shade still read. The dye is a gingham weave over the sheet's grid
// (v_uv, cells: two-cell bands of u_tint in each direction over a white ground, half strength
// where one band crosses the ground) or plain.
in vec3 v_normal;
in vec3 v_world;
in vec3 v_world_normal;
in vec3 v_color;
in vec2 v_uv;
in vec3 v_eye;

uniform vec3 u_light;  // unit direction towards the light, eye space
uniform float u_ambient;
uniform bool u_gingham;
uniform float u_sheen;            // sheen reflectance (white); 0: none
uniform float u_sheen_roughness;  // Charlie alpha

layout(location = 0) out vec4 o_color;

// A band of width 1/2 of each period, anti-aliased over one pixel's footprint.
float band(float x) {
  float w = max(fwidth(x), 1e-4);
  float f = fract(x);
  return clamp((min(f, 1.0 - f) - 0.25) / w + 0.5, 0.0, 1.0);  // 1 inside [0.25, 0.75)
}

vec3 dye(vec3 tint) {
  if (!u_gingham) return tint;
  vec2 q = v_uv / 4.0;  // bands of two cells, period four
  float k = 0.5 * (band(q.x) + band(q.y));
  return mix(vec3(0.92, 0.91, 0.88), tint, k);
}

void main() {
  vec3 n = normalize(v_normal);
  vec3 nw = normalize(v_world_normal);
  if (!gl_FrontFacing) n = -n, nw = -nw;  // the side being seen
  vec3 V = normalize(-v_eye);
  vec3 light = shadow_light(v_world, nw, gl_FragCoord.xy);
  vec3 albedo = srgb_to_linear(dye(v_color));
  float NL = max(dot(n, u_light), 0.0), NV = max(dot(n, V), 1e-3);
  vec3 H = normalize(u_light + V);
  float NH = max(dot(n, H), 0.0);
  // Charlie: D = (2 + 1/a) sin(theta_h)^(1/a) / (2 pi); V = 1 / (4 (NL + NV - NL NV)).
  float inv_a = 1.0 / u_sheen_roughness;
  float sin_h = sqrt(max(1.0 - NH * NH, 0.0));
  float D = (2.0 + inv_a) * pow(sin_h, inv_a) / (2.0 * 3.14159265);
  float vis = 1.0 / (4.0 * (NL + NV - NL * NV) + 1e-4);
  // Lambert albedo / pi and the sheen under irradiance pi (1 - ambient) NL: the light's share.
  vec3 direct = (albedo + vec3(u_sheen * D * vis * 3.14159265)) * (1.0 - u_ambient) * NL * light;
  vec3 ambient = albedo * u_ambient * (0.75 + 0.25 * dot(n, u_light));
  o_color = vec4(linear_to_srgb(direct + ambient), 1.0);
}
