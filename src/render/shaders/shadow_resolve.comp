// Shadow pass 4: the maps the receivers read (shadow.glsl). The opaque map (R32F, metres below
// z0 of the nearest opaque caster; 1e30 = none) from the rasterised casters' depth; the fluid map
// (RG32F: front depth, path in fluid along the light) from the particle splat, in the splat's
// texel grid (its coarser level: the first (size >> k)^2 texels). Particles drawn as opaque
// spheres (render.fluid: particles) go into the opaque map instead, read at this texel's parent.
// The splat images are cleared by shadow_clear.comp before the next splat.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform readonly uimage2D u_shadow_bits;
layout(r32ui, binding = 1) uniform readonly uimage2D u_shadow_thick;
layout(r32f, binding = 2) uniform writeonly image2D u_map;
layout(rg32f, binding = 3) uniform writeonly image2D u_fluid_map;
uniform sampler2D u_mesh_depth;   // window depth 0..1 over the casters' range; 1 = none
uniform bool u_has_mesh;          // false: no mesh casters this frame, u_mesh_depth not drawn
uniform bool u_has_splat;
uniform bool u_splat_opaque;
uniform float u_splat_radius;
uniform float u_metres_per_unit;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(u_map)))) return;
  LightMap m = light_map();
  float d = 1e30;
  float w = u_has_mesh ? texelFetch(u_mesh_depth, p, 0).r : 1.0;
  if (w < 1.0) d = w * m.range;
  vec2 fluid = vec2(1e30, 0.0);
  if (u_has_splat) {
    if (u_splat_opaque) {
      uint b = imageLoad(u_shadow_bits, p >> splat_level(m, u_splat_radius)).r;
      if (b != 0xffffffffu) d = min(d, uintBitsToFloat(b));
    } else {
      uint b = imageLoad(u_shadow_bits, p).r;
      if (b != 0xffffffffu) fluid = vec2(uintBitsToFloat(b), float(imageLoad(u_shadow_thick, p).r) * u_metres_per_unit);
    }
  }
  imageStore(u_map, p, vec4(d));
  imageStore(u_fluid_map, p, vec4(fluid, 0.0, 0.0));
}
