// SSFR shading (van der Laan et al. 2009, section 4.4), in linear radiance (color.glsl): what is
// behind the water seen through it (refraction by Snell's law, attenuated by Beer-Lambert over the
// path in water), the surroundings reflected by it, mixed by Schlick's Fresnel approximation,
// plus the reflection of the light itself (a GGX microfacet highlight). Also writes reflection
// and refraction alone for the stage images (the dissertation's Figure 4.5).
uniform sampler2D u_scene_color;
uniform sampler2D u_scene_depth;  // window depth of the scene and objects behind the fluid
uniform sampler2D u_fluid_depth;
uniform sampler2D u_normal;
uniform sampler2D u_thickness;
uniform samplerCube u_cube;
uniform bool u_use_cube;       // mesh view: cube map of the scene; Kinect view: u_env
uniform vec3 u_env;            // Kinect view: the image's mean colour, linear
uniform mat3 u_world_R_eye;
uniform vec3 u_absorption;     // 1/m per channel
uniform float u_ior;           // refractive index of the fluid (water 1.33)
uniform float u_f0;            // reflectance at normal incidence
uniform float u_roughness;     // GGX alpha of the surface (after the depth filter)
uniform float u_light_intensity;  // a white diffuse surface facing the light alone: this radiance
uniform vec3 u_light;          // towards the light, eye space

float schlick(float f0, float cos_theta) { return f0 + (1.0 - f0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0); }

// Texture coordinates of the framebuffer pixel that eye point q projects to.
vec2 project_uv(vec3 q) {
  vec2 px = vec2(u_K.x * q.x / q.z + u_K.z, u_K.y * q.y / q.z + u_K.w);
  return vec2(px.x + 0.5, u_size.y - (px.y + 0.5)) / u_size;  // window rows run up
}

// The shaded colour at texel p, and reflection and refraction alone (ssfr_composite.frag / .comp).
void composite_at(ivec2 p, out vec4 o_color, out vec4 o_reflect, out vec4 o_refract) {
  vec2 frag = vec2(p) + 0.5;  // gl_FragCoord.xy of this texel
  vec3 scene = texelFetch(u_scene_color, p, 0).rgb;
  float z = texelFetch(u_fluid_depth, p, 0).r;
  if (z <= 0.0) {
    o_color = vec4(scene, 1.0);
    o_reflect = o_refract = vec4(0.0, 0.0, 0.0, 1.0);
    return;
  }
  vec3 P = z * pixel_ray(texel_pixel(p));
  vec3 V = normalize(-P);
  vec3 N = texelFetch(u_normal, p, 0).xyz;
  float NV = max(dot(N, V), 1e-3);
  // Thickness may be at reduced resolution: bilinear upsampling (it is smooth: a blurred sum of
  // chords), and only read where the full-resolution depth has fluid.
  float T = texture(u_thickness, frag / u_size).r;

  // Refraction: the view ray bends at the surface (Snell) and meets what is behind the fluid
  // after the path in water: where the scene behind this pixel is (fluid resting on a surface: the
  // surface itself), or the fluid's thickness (fluid in the air: the ray leaves it there and goes
  // on nearly parallel). That point, projected, is what this pixel shows, so the displacement
  // grows with depth and with the tilt of the surface, as through real water.
  vec3 t = refract(-V, N, 1.0 / u_ior);
  float z_bg = eye_depth(texelFetch(u_scene_depth, p, 0).r);
  float path = min(T, max(z_bg - P.z, 0.0) / max(t.z, 0.2));
  vec3 Q = P + t * path;
  vec2 uv_t = clamp(project_uv(Q), 0.5 / u_size, 1.0 - 0.5 / u_size);
  // Beer-Lambert: each metre of water keeps exp(-absorption) of the light, per channel.
  vec3 refr = srgb_to_linear(texture(u_scene_color, uv_t).rgb) * exp(-u_absorption * T);

  // Reflection of the surroundings: the scene's cube map; in the Kinect view only the camera's
  // own picture exists, whose mean colour stands for the room's light reflected off the surface.
  vec3 R = reflect(-V, N);
  vec3 refl = u_use_cube ? srgb_to_linear(texture(u_cube, u_world_R_eye * R).rgb) : u_env;
  float F = schlick(u_f0, NV);

  // The light's own reflection: GGX microfacets (Walter et al. 2007) with Schlick's Fresnel and
  // the Smith-Schlick visibility term; the light's irradiance E = pi * u_light_intensity (a
  // white Lambertian surface it lights head-on would show u_light_intensity).
  vec3 H = normalize(u_light + V);
  float NL = max(dot(N, u_light), 0.0), NH = max(dot(N, H), 0.0);
  float a2 = u_roughness * u_roughness;
  float D = a2 / (3.14159265 * pow(NH * NH * (a2 - 1.0) + 1.0, 2.0));
  float k = 0.5 * u_roughness;
  float vis = 1.0 / ((NL * (1.0 - k) + k) * (NV * (1.0 - k) + k));  // G / (NL NV)
  float spec = schlick(u_f0, dot(V, H)) * D * vis * 0.25 * NL * 3.14159265 * u_light_intensity;

  vec3 c = mix(refr, refl, F) + vec3(spec);
  o_color = vec4(linear_to_srgb(c), 1.0);
  o_reflect = vec4(linear_to_srgb(refl), 1.0);
  o_refract = vec4(linear_to_srgb(refr), 1.0);
}
