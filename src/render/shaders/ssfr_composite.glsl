// SSFR shading (van der Laan et al. 2009, section 4.4): refraction of the scene behind through
// the fluid's thickness with Beer-Lambert attenuation, reflection of the surroundings, mixed by
// Schlick's Fresnel approximation, plus a specular highlight. Also writes reflection and
// refraction alone for the stage images (the dissertation's Figure 4.5).
uniform sampler2D u_scene_color;
uniform sampler2D u_fluid_depth;
uniform sampler2D u_normal;
uniform sampler2D u_thickness;
uniform samplerCube u_cube;
uniform bool u_use_cube;       // mesh view: cube map of the scene; Kinect view: the image itself
uniform mat3 u_world_R_eye;
uniform vec3 u_absorption;     // 1/m per channel
uniform float u_refraction;    // screen fraction per metre of thickness
uniform float u_f0;
uniform vec3 u_light;          // towards the light, eye space

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
  // Thickness may be at reduced resolution: bilinear upsampling (it is smooth: a blurred sum of
  // chords), and only read where the full-resolution depth has fluid.
  float T = texture(u_thickness, frag / u_size).r;
  vec2 uv = frag / u_size;
  // Thicker fluid bends the background further; eye y runs down, texture v up.
  vec2 uv_t = clamp(uv + vec2(N.x, -N.y) * u_refraction * T, 0.0, 1.0);
  vec3 refr = texture(u_scene_color, uv_t).rgb * exp(-u_absorption * T);
  vec3 R = reflect(-V, N);
  vec3 refl = u_use_cube ? texture(u_cube, u_world_R_eye * R).rgb
                         : texture(u_scene_color, clamp(uv + vec2(R.x, -R.y) * 0.1, 0.0, 1.0)).rgb;
  float F = u_f0 + (1.0 - u_f0) * pow(1.0 - max(dot(N, V), 0.0), 5.0);
  float spec = pow(max(dot(N, normalize(u_light + V)), 0.0), 64.0);
  o_color = vec4(mix(refr, refl, F) + vec3(0.5 * spec), 1.0);
  o_reflect = vec4(refl, 1.0);
  o_refract = vec4(refr, 1.0);
}
