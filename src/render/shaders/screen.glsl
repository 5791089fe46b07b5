// Full-screen passes as compute shaders (GL 4.3): one invocation per texel of the output image, in
// 8 x 8 tiles. Same per-texel functions as the fragment versions (ssfr_*.glsl); compute runs on
// every SM of a GH100, fragments only on its few graphics TPCs (docs/RENDERING.md, Speed).
layout(local_size_x = 8, local_size_y = 8) in;

// This invocation's texel, or false when the tile reaches past an image of this size.
bool screen_texel(ivec2 size, out ivec2 p) {
  p = ivec2(gl_GlobalInvocationID.xy);
  return all(lessThan(p, size));
}
