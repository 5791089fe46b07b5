// The largest depth bits of each 4 x 4 pixel tile of the fluid depth splat's image after its
// occluders (ssfr_depth_splat.comp, pass 2's test); 0xffffffff where any pixel of the tile has no
// fluid yet. Window coordinates, like the image.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform readonly uimage2D u_depth_bits;
layout(r32ui, binding = 1) uniform writeonly uimage2D u_depth_tiles;

void main() {
  ivec2 t = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(t, imageSize(u_depth_tiles)))) return;
  ivec2 size = imageSize(u_depth_bits);
  uint m = 0u;
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 4; ++x) {
      ivec2 p = 4 * t + ivec2(x, y);
      if (all(lessThan(p, size))) m = max(m, imageLoad(u_depth_bits, p).r);
    }
  imageStore(u_depth_tiles, t, uvec4(m));
}
