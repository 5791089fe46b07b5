// Shadow pass 4: one R32F map (metres below z0; 1e30 = no caster) from the rasterised casters'
// depth (full resolution) and the particle splat (its coarser level, read at this texel's
// parent). The splat image is cleared by the host before the next splat.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform readonly uimage2D u_shadow_bits;
layout(r32f, binding = 1) uniform writeonly image2D u_map;
uniform sampler2D u_mesh_depth;   // window depth 0..1 over the casters' range; 1 = none
uniform bool u_has_splat;
uniform float u_splat_radius;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(u_map)))) return;
  LightMap m = light_map();
  float d = 1e30;
  float w = texelFetch(u_mesh_depth, p, 0).r;
  if (w < 1.0) d = w * m.range;
  if (u_has_splat) {
    uint b = imageLoad(u_shadow_bits, p >> splat_level(m, u_splat_radius)).r;
    if (b != 0xffffffffu) d = min(d, uintBitsToFloat(b));
  }
  imageStore(u_map, p, vec4(d));
}
