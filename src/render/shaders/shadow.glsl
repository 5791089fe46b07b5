// Shadows of the virtual objects (rigid bodies, cloth, fluid) from one directional light
// (docs/RENDERING.md, pass "shadow"; renderer_shadow.cpp). Only virtual objects are casters: the
// real scene already shows its own shadows, so the map never holds it.
//
// The light frame has x and y across the light and z along the direction it travels; u_light_R
// maps world coordinates into it. The map is orthographic over the casters' bounds in that frame,
// found each frame on the GPU (shadow_bounds.comp, no read-back), so every user decodes them
// here. Map values are metres along the light below the nearest caster's front (z0).
uniform mat3 u_light_R;
uniform isampler2D u_light_bounds;  // 6 x 1 texels: lo.x lo.y lo.z hi.x hi.y hi.z as order_int()
uniform float u_shadow_size;        // map texels per side

// Floats as ints with the same order, for atomic min/max of signed values: a negative float's
// magnitude bits are reversed so that a larger magnitude gives a smaller int.
int order_int(float f) {
  int b = floatBitsToInt(f);
  return b >= 0 ? b : b ^ 0x7fffffff;
}
float order_float(int o) { return intBitsToFloat(o >= 0 ? o : o ^ 0x7fffffff); }

struct LightMap {
  vec2 lo;       // light x, y of the map's corner (texel (0, 0)'s outer corner)
  float extent;  // metres per side (square texels)
  float texel;   // metres per texel
  float z0;      // light z of map depth 0: the casters' front
  float range;   // casters' depth span, metres (the rasterised casters' depth range)
  bool valid;    // false: nothing casts a shadow this frame
};

LightMap light_map() {
  vec3 lo, hi;
  for (int i = 0; i < 3; ++i) {
    lo[i] = order_float(texelFetch(u_light_bounds, ivec2(i, 0), 0).r);
    hi[i] = order_float(texelFetch(u_light_bounds, ivec2(i + 3, 0), 0).r);
  }
  LightMap m;
  m.valid = all(lessThanEqual(lo, hi));
  // Square texels, and two empty texels on each side: filters that reach past the casters read
  // "no caster" there instead of the clamped edge.
  float e = max(max(hi.x - lo.x, hi.y - lo.y), 1e-3);
  m.texel = e / (u_shadow_size - 4.0);
  m.extent = m.texel * u_shadow_size;
  m.lo = 0.5 * (lo.xy + hi.xy) - 0.5 * m.extent;
  m.z0 = lo.z;
  m.range = max(hi.z - lo.z, 1e-3);
  return m;
}

// Map coordinates (0..1 across the map) and depth below z0 (metres) of a world point.
vec3 light_coords(LightMap m, vec3 world) {
  vec3 q = u_light_R * world;
  return vec3((q.xy - m.lo) / m.extent, q.z - m.z0);
}

// Particles are splatted into a coarser level of the map (every 2^k-th texel) with k such that a
// sphere's radius spans 2 to 4 texels there: a splat then touches at most (2 * 4 + 1)^2 texels,
// not (2 r / texel)^2 (a 2 cm sphere in a map of 0.25 mm texels: 25 000), with two atomics each
// (depth, path). Spheres packed one particle diameter apart (radius 1.5 r, the fluid passes' size)
// leave no gap a texel centre could fall into (the farthest point from 4 lattice neighbours is
// sqrt(2) r from each), and the fluid's shadow is soft anyway (bilinear over these texels).
const float kSplatTexelsPerRadius = 2.0;
int splat_level(LightMap m, float radius) {
  return clamp(int(ceil(log2(radius / (kSplatTexelsPerRadius * m.texel)))), 0, 14);
}

#ifdef SEAMLESS_SHADOW_CASTER
// Clip position of a caster vertex in the map: orthographic, depth 0..range to -1..1.
vec4 light_clip(vec3 world) {
  LightMap m = light_map();
  vec3 c = light_coords(m, world);
  return vec4(c.xy * 2.0 - 1.0, c.z / m.range * 2.0 - 1.0, 1.0);
}
#else
uniform bool u_shadow_on;           // a map was made this frame (render.shadows and casters drawn)
uniform sampler2D u_shadow_map;     // metres below z0 of the nearest opaque caster; 1e30 = none
uniform bool u_opaque_shadow_on;    // u_shadow_map holds opaque casters this frame (else all 1e30)
uniform bool u_fluid_shadow_on;     // the fluid is in u_fluid_shadow this frame
uniform sampler2D u_fluid_shadow;   // in the fluid splat's texel grid: front depth (1e30 = none), path in fluid
uniform float u_fluid_radius;       // the fluid spheres' radius (their splat level)
uniform vec3 u_shadow_absorption;   // the fluid's Beer-Lambert coefficients, 1/m (render.absorption)
uniform float u_light_tan;          // tan of half the light's angular diameter (render.light_angle)
uniform float u_shadow_strength;    // render.shadow_strength

// Interleaved gradient noise (Jimenez 2014): a per-pixel rotation of the filter taps that turns
// the banding of few taps into fine, deterministic noise.
float shadow_ign(vec2 px) { return fract(52.9829189 * fract(dot(px, vec2(0.06711056, 0.00583715)))); }

// Tap i of n on a Vogel spiral (evenly spread over the unit disc), rotated by phi.
vec2 vogel(int i, int n, float phi) {
  float r = sqrt((float(i) + 0.5) / float(n));
  float a = float(i) * 2.39996323 + phi;  // the golden angle
  return r * vec2(cos(a), sin(a));
}

// Texel coordinate t (texel centres at integers) -> the gather position of its bilinear
// footprint and the four texels' weights (textureGather's order: (i0, j1), (i1, j1), (i1, j0),
// (i0, j0)).
vec2 gather_at(vec2 t, out vec4 w) {
  vec2 f = fract(t);
  w = vec4((1.0 - f.x) * f.y, f.x * f.y, f.x * (1.0 - f.y), (1.0 - f.x) * (1.0 - f.y));
  return (floor(t) + 1.0) / u_shadow_size;
}

// Fraction (0..1) of the light an opaque caster hides from the point at light coordinates c:
// percentage-closer soft shadows (Fernando 2005). A directional light of angular radius a gives a
// penumbra of radius tan(a) (d_receiver - d_blocker): sharp where an object touches the surface
// (the contact shadow), softer further away. Steps: the mean depth of the blockers found within
// the largest possible penumbra, then percentage-closer filtering (Reeves et al. 1987) over the
// penumbra it predicts. slope: the receiver's depth change per metre across the light.
float opaque_shadow(LightMap m, vec3 c, vec2 slope, float bias, float phi) {
  // Blocker search: a caster at depth 0 hides part of the light from up to tan(a) c.z away.
  float search = u_light_tan * c.z + 2.0 * m.texel;  // metres
  float sum = 0.0, count = 0.0;
  for (int i = 0; i < 16; ++i) {
    vec2 o = vogel(i, 16, phi) * search;
    vec4 w;
    vec4 d = textureGather(u_shadow_map, gather_at((c.xy + o / m.extent) * u_shadow_size - 0.5, w));
    vec4 blocked = step(d, vec4(c.z - bias + dot(slope, o)));
    sum += dot(blocked, d);
    count += dot(blocked, vec4(1.0));
  }
  if (count == 0.0) return 0.0;
  // Penumbra from the mean blocker depth; at least one texel, which hides the map's staircase.
  float radius = u_light_tan * max(c.z - sum / count, 0.0) + m.texel;
  float shadow = 0.0;
  for (int i = 0; i < 32; ++i) {
    vec2 o = vogel(i, 32, phi) * radius;
    vec4 w;
    vec4 d = textureGather(u_shadow_map, gather_at((c.xy + o / m.extent) * u_shadow_size - 0.5, w));
    shadow += dot(w, step(d, vec4(c.z - bias + dot(slope, o))));
  }
  return shadow / 32.0;
}

// What of the light passes the fluid between the light and the point, per channel: water is
// transparent, so its shadow is the light it absorbs on the way (Beer-Lambert over the light's
// path in fluid: the summed chords of its spheres, as the camera's thickness), a tinted shadow,
// not a black one. Bilinear in the splat's grid (texels of about a quarter sphere radius: soft
// enough for the fluid's rounded outline). The light refraction gathers into caustics and the
// few per cent the surface reflects are left out.
vec3 fluid_transmittance(LightMap m, vec3 c, float bias) {
  float size_k = float(int(u_shadow_size) >> splat_level(m, u_fluid_radius));
  vec4 w;
  vec2 at = gather_at(c.xy * size_k - 0.5, w);
  vec4 d = textureGather(u_fluid_shadow, at, 0), path = textureGather(u_fluid_shadow, at, 1);
  vec3 t = vec3(0.0);
  for (int i = 0; i < 4; ++i) t += w[i] * (d[i] < c.z - bias ? exp(-u_shadow_absorption * path[i]) : vec3(1.0));
  return t;
}

// The share of the light that reaches the world point past the virtual objects, per channel (1:
// all of it). n: the receiver's unit world normal, or (0, 0, 0) where it is unknown (the Kinect
// image). pixel: the frame pixel, seeds the filter taps' rotation.
vec3 shadow_light(vec3 world, vec3 n, vec2 pixel) {
  if (!u_shadow_on) return vec3(1.0);
  LightMap m = light_map();
  if (!m.valid) return vec3(1.0);
  vec3 nl = u_light_R * n;
  bool has_normal = dot(n, n) > 0.0;
  // A surface turned away from the light gets none of it: nothing to take away.
  if (has_normal && nl.z >= 0.0) return vec3(1.0);
  // Depth bias. Receivers are either the real scene, which is never in the map, or virtual
  // surfaces, which are: the map holds their own depth at the texel centres. For those the
  // reference depth follows the receiver's plane across the filter (receiver-plane depth bias,
  // slope clamped at grazing angles) and the point moves one texel off its surface; what is
  // left is the map's spacing: 1.5 texels of depth per unit of slope. The constant 1 mm keeps a
  // surface resting on a virtual object (or sunk a little into it) from shadowing itself.
  vec2 slope = vec2(0.0);
  if (has_normal) {
    slope = -nl.xy / min(nl.z, -0.2);
    world += n * m.texel;
  }
  float bias = 1.5 * m.texel * (1.0 + length(slope)) + 1e-3;
  vec3 c = light_coords(m, world);
  if (c.z <= 0.0 || any(lessThan(c.xy, vec2(0.0))) || any(greaterThan(c.xy, vec2(1.0)))) return vec3(1.0);
  // Without opaque casters (fluid alone, drawn as a surface) the map is 1e30 everywhere and the
  // blocker search could find nothing: its 16 taps a pixel are skipped, with the same result.
  vec3 light = vec3(1.0);
  if (u_opaque_shadow_on) light -= opaque_shadow(m, c, slope, bias, 6.2831853 * shadow_ign(pixel));
  if (u_fluid_shadow_on) light *= fluid_transmittance(m, c, bias);
  return light;
}

// What the shadow leaves of a colour whose light is all accounted for (the camera image, the
// unlit scan): u_shadow_strength is the share of the light at the surface that came from this
// light, of which `light` is left; the rest is the room's other light, of which the bodies hide
// the share `occluded` (occlusion.glsl); applied to linear radiance.
vec3 shadowed_srgb(vec3 srgb, vec3 light, float occluded) {
  if (all(greaterThanEqual(light, vec3(1.0))) && occluded <= 0.0) return srgb;
  float s = u_shadow_strength;
  return linear_to_srgb(srgb_to_linear(srgb) * (s * light + (1.0 - s) * (1.0 - occluded)));
}
#endif
