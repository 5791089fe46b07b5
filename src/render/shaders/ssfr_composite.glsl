// SSFR shading (van der Laan et al. 2009, section 4.4), in linear radiance (color.glsl): what is
// behind the water seen through it (refraction by Snell's law, attenuated by Beer-Lambert over the
// path in water, darkened where the water wets the surface it rests on), the surroundings
// reflected by it (traced in screen space, else the environment), mixed by Schlick's Fresnel
// approximation, plus the reflection of the light itself (a GGX microfacet highlight). Also writes
// reflection and refraction alone for the stage images (the dissertation's Figure 4.5).
uniform sampler2D u_scene_color;
uniform sampler2D u_scene_depth;  // window depth of the scene and objects behind the fluid
uniform sampler2D u_fluid_depth;
uniform sampler2D u_normal;
uniform sampler2D u_thickness;
uniform samplerCube u_cube;
uniform bool u_use_cube;       // mesh view: cube map of the scene; Kinect view: u_env
uniform vec3 u_env;            // Kinect view: the image's mean colour, linear
uniform bool u_image_env;      // Kinect view: the image as the environment (else u_env)
uniform mat3 u_world_R_eye;
uniform vec3 u_absorption;     // 1/m per channel
uniform float u_ior;           // refractive index of the fluid (water 1.33)
uniform float u_f0;            // reflectance at normal incidence
uniform float u_roughness;     // GGX alpha of the surface (after the depth filter)
uniform float u_light_intensity;  // a white diffuse surface facing the light alone: this radiance
uniform vec3 u_light;          // towards the light, eye space
uniform int u_ssr_steps;       // screen-space reflection: steps along the reflected ray; 0 = off
uniform float u_ssr_distance;  // ... over this many metres
uniform float u_contact;       // metres: water whose back is this close to the scene wets it
uniform bool u_wet;            // darken the surface under the water (Lekner & Dorf 1988)
uniform bool u_depth_holes;    // Kinect view: scene window depth 1 is a pixel without recorded depth
uniform float u_diffuse_share; // share of a real surface's light that the fluid's shadow does not already attenuate
uniform float u_drop_radius;   // metres: a lone drop's sphere (splat.glsl)

float schlick(float f0, float cos_theta) { return f0 + (1.0 - f0) * pow(1.0 - clamp(cos_theta, 0.0, 1.0), 5.0); }

// Texture coordinates of the framebuffer pixel that eye point q projects to.
vec2 project_uv(vec3 q) {
  vec2 px = vec2(u_K.x * q.x / q.z + u_K.z, u_K.y * q.y / q.z + u_K.w);
  return vec2(px.x + 0.5, u_size.y - (px.y + 0.5)) / u_size;  // window rows run up
}

float scene_eye_depth(vec2 uv) { return eye_depth(texelFetch(u_scene_depth, ivec2(uv * u_size), 0).r); }

// Screen-space reflection (the linear ray march of McGuire & Mara 2014, "Efficient GPU Screen-Space
// Ray Tracing", in eye space): the reflected ray from P is followed in u_ssr_steps equal steps over
// u_ssr_distance; the first step whose point lies behind the scene depth at its pixel, by less than
// the step's own depth change plus 5 cm (the scene is a height field: further behind is hidden
// space, not a hit), is refined by bisection. Returns the hit's weight (0: no hit), faded towards
// the image border and the ray's end so that the fallback takes over smoothly, and its uv.
float trace_reflection(vec3 P, vec3 R, out vec2 uv) {
  uv = vec2(0.0);
  if (u_ssr_steps <= 0) return 0.0;
  float ds = u_ssr_distance / float(u_ssr_steps);
  float tol = abs(R.z) * ds + 0.05;
  float s0 = 0.0;
  for (int i = 1; i <= u_ssr_steps; ++i) {
    float s = ds * float(i);
    vec3 q = P + R * s;
    if (q.z <= u_near_far.x) return 0.0;
    vec2 u = project_uv(q);
    if (any(lessThan(u, vec2(0.0))) || any(greaterThanEqual(u, vec2(1.0)))) return 0.0;
    float dz = q.z - scene_eye_depth(u);
    if (dz > 0.0 && dz < tol) {
      float lo = s0, hi = s;  // the surface is crossed between lo and hi
      for (int k = 0; k < 5; ++k) {
        float m = 0.5 * (lo + hi);
        vec3 qm = P + R * m;
        if (qm.z - scene_eye_depth(project_uv(qm)) > 0.0) hi = m;
        else lo = m;
      }
      uv = project_uv(P + R * hi);
      vec2 border = min(uv, 1.0 - uv) * u_size;  // pixels to the nearest image edge
      return clamp(min(border.x, border.y) / 16.0, 0.0, 1.0) * (1.0 - smoothstep(0.7, 1.0, hi / u_ssr_distance));
    }
    s0 = s;
  }
  return 0.0;
}

// The Kinect view's environment where the traced ray finds nothing: the room at infinity as the
// camera itself saw it, i.e. the image pixel that direction R points to from the camera (a
// direction behind the camera is mirrored into the image plane, R.z -> |R.z|; one beyond the image
// reads its nearest edge). A puddle on a desk then reflects what stands beyond it, with the room's
// own colours and contrast, where a constant (the image's mean colour) made a flat grey sheen.
vec3 image_environment(vec3 R) {
  vec2 uv = project_uv(vec3(R.xy, max(abs(R.z), 0.2)));
  return srgb_to_linear(texture(u_scene_color, clamp(uv, 0.5 / u_size, 1.0 - 0.5 / u_size)).rgb);
}

// A diffuse surface under water is darker than dry (Lekner & Dorf 1988, "Why some things are darker
// when wet", Appl. Opt. 27): of the light that enters the water (1 - R_e), the surface of albedo a
// sends up a; the water-air interface sends R_i of that back down (total internal reflection), so
// the surface's radiosity is a E (1 - R_e) / (1 - a R_i), and the radiance leaving the water is
// (1 - F_view) / n^2 of the surface's (the n^2 law of radiance). R_e, the reflectance for diffuse
// light from above, is Schlick's Fresnel averaged over the hemisphere (cosine-weighted):
// f0 + (1 - f0) / 21; R_i = 1 - (1 - R_e) / n^2 by reciprocity. This returns the factor on the dry
// radiance apart from (1 - F_view), which the Fresnel mix applies. The albedo is taken as the
// surface's linear radiance (clamped to 1): the image holds no other measure of it; a darker
// surface darkens more, relatively, as it does when wet.
// Absorbing water (Lekner & Dorf's water is clear): the light sent back down by the interface
// crosses the layer of depth h twice before it meets the surface again; diffuse light in water
// (cosine-weighted over the hemisphere) travels on average h / mu = 2 h to a plane h away (mean
// cosine mu = 1/2), so each round trip keeps tau_r = exp(-absorption 4 h) and the series sums to
// 1 / (1 - a R_i tau_r). (A first-order estimate: the share R_i is mostly totally reflected,
// grazing light, whose paths are longer.)
vec3 wet_factor(vec3 dry, vec3 tau_r) {
  float n2 = u_ior * u_ior;
  float Re = u_f0 + (1.0 - u_f0) / 21.0;
  float Ri = 1.0 - (1.0 - Re) / n2;
  return vec3((1.0 - Re) / n2) / (1.0 - clamp(dry, 0.0, 1.0) * Ri * tau_r);
}

// Mean cosine of the light just under a flat water surface lit by a uniform sky: the refracted
// directions fill the cone of the critical angle theta_c (sin theta_c = 1 / n) with radiance
// weighted by cos theta sin theta, so mu_d = E_d / E_0 = (sin^2 theta_c / 2) / (1 - cos theta_c)
// = 0.83 for n = 1.33 (the downwelling average cosine of hydrologic optics: Kirk 1994, "Light and
// Photosynthesis in Aquatic Ecosystems", 2nd ed., ch. 6; Mobley 1994, "Light and Water", ch. 1);
// diffuse light reaching a depth h has come h / mu_d through the water on average.
float downwelling_mean_cosine() {
  float s2 = 1.0 / (u_ior * u_ior);
  return 0.5 * s2 / (1.0 - sqrt(1.0 - s2));
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
  // chords), and only read where the full-resolution depth has fluid. A lone drop (splat.glsl) is
  // a sphere of u_drop_radius whose depth and normals are its own (the filter leaves it as
  // splatted): the view ray, entering at theta_v to the normal, crosses it over the chord
  // 2 r cos theta_v. (The blurred thickness would spread the drop's chords over the filter's width.)
  // A drop lying flat (splat.glsl, "Lone drops at rest") is a cap as wide as that blur: its path
  // is the thickness pass's, and it rests on the surface under it, by construction.
  bool flat_drop = is_flat_drop(z), bead = is_drop(z) && !flat_drop;
  float T = bead ? 2.0 * u_drop_radius * NV : texture(u_thickness, frag / u_size).r;

  // The water's depth along its normal: the thickness pass measures T, the path of the view ray
  // through the water, and a locally plane-parallel layer of depth h is crossed over h / cos
  // theta_v, so h = T cos theta_v (theta_v between the view ray and the normal).
  float h = T * NV;
  vec3 t = refract(-V, N, 1.0 / u_ior);
  float cos_t = max(-dot(t, N), 0.1);  // >= cos(critical angle) = 0.66 for water

  // Does the water rest on the surface behind it (its back within u_contact of the scene along the
  // view ray)? Then it wets it; a drop in the air does not. The measured depth is noisy and
  // quantised (a Kinect v1's step is about 2.85e-3 z^2 m: 1.1 cm at 2 m), so the tolerance grows
  // with z^2 and the fade spans twice it: a sharp threshold drew the depth's quantisation bands as
  // stripes.
  // A pixel without recorded depth (a Kinect hole: a glossy table at a grazing angle, a dark or
  // too near surface) is not an occluder, so the water is drawn there, but nor is it a surface
  // infinitely far away: the camera saw something there, in its colour, at a depth it did not
  // measure. Taken as infinitely far, the water there counted as hanging in the air (not wet, its
  // refracted ray run through the whole thickness and projected away from the pixel): blocks
  // unlike the water around them, exactly where the depth has holes. The nearest surface
  // consistent with seeing the water there is right behind it: the water's back along the view
  // ray, so it rests on it, as on the measured pixels around.
  float w_bg = texelFetch(u_scene_depth, p, 0).r;
  float z_bg = u_depth_holes && w_bg >= 1.0 ? P.z * (1.0 + T / length(P)) : eye_depth(w_bg);
  float gap = max(z_bg - P.z, 0.0) * length(P) / P.z - T;
  float tol = u_contact + 0.006 * z_bg * z_bg;
  // A bead (a lone drop in the air; at rest it lies flat) is shaded as water in the air (a convex
  // lens: refracted, reflecting at its rim, the light's highlight on it), not as a wet film.
  float resting = bead ? 0.0 : flat_drop ? 1.0 : 1.0 - smoothstep(tol, 3.0 * tol, gap);

  // The refracted view ray's path in the water. Water resting on a surface is a layer: the ray
  // bends (Snell, t = refract(-V, N, 1 / n)) and crosses it over h / cos theta_t (at most 1.51 h,
  // however grazing the view, where the view ray's chord T grows without bound). Water in the air
  // keeps the chord T: through a convex drop the refracted path is T cos theta_t / cos theta_v,
  // through a slab T cos theta_v / cos theta_t, and T lies between the two.
  float view_path = mix(T, h / cos_t, resting);
  // Refraction: the ray meets what is behind the water after that path, or the scene where it is
  // nearer (water resting on it). That point, projected, is what this pixel shows, so the
  // displacement grows with depth and with the tilt of the surface, as through real water.
  float path = min(view_path, max(z_bg - P.z, 0.0) / max(t.z, 0.2));
  vec3 Q = P + t * path;
  vec2 uv_t = clamp(project_uv(Q), 0.5 / u_size, 1.0 - 0.5 / u_size);
  vec3 behind = srgb_to_linear(texture(u_scene_color, uv_t).rgb);
  // Beer-Lambert (each metre of water keeps exp(-absorption) of the light, per channel) along the
  // paths the light takes. Every pixel: the refracted view ray, view_path. Under resting water,
  // also the light's way down to the surface, which the camera image (the dry surface) does not
  // hold: the room's diffuse light crosses h / mu_d on average (downwelling_mean_cosine); the
  // light's own share is attenuated by the fluid's shadow already (shadow.glsl), so only
  // u_diffuse_share of the light is attenuated here; and the internal reflections (wet_factor).
  vec3 tau_down = vec3(1.0) - u_diffuse_share * (vec3(1.0) - exp(-u_absorption * (h / downwelling_mean_cosine())));
  vec3 under = tau_down * (u_wet ? wet_factor(behind, exp(-u_absorption * (4.0 * h))) : vec3(1.0));
  vec3 refr = behind * mix(vec3(1.0), under, resting) * exp(-u_absorption * view_path);

  // Reflection of the surroundings: what the reflected ray meets on screen (the scene and the other
  // objects), else the scene's cube map (mesh view) or, in the Kinect view, the image as an
  // environment at infinity (image_environment); u_image_env false: the image's mean colour.
  vec3 R = reflect(-V, N);
  vec3 env = u_use_cube ? srgb_to_linear(texture(u_cube, u_world_R_eye * R).rgb)
                        : (u_image_env ? image_environment(R) : u_env);
  vec2 uv_r;
  float hit = trace_reflection(P, R, uv_r);
  vec3 refl = hit > 0.0 ? mix(env, srgb_to_linear(texture(u_scene_color, uv_r).rgb), hit) : env;
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
