// Shadow pass 3, before the splat: the splat images back to "no fluid" (depth bits all ones, path
// 0). A compute pass writes them at the memory's speed, where glClearTexImage on these integer
// images cost 0.3 ms each at 2048^2 (docs/PERFORMANCE.md, the live loop).
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform writeonly uimage2D u_shadow_bits;
layout(r32ui, binding = 1) uniform writeonly uimage2D u_shadow_thick;

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(u_shadow_bits)))) return;
  imageStore(u_shadow_bits, p, uvec4(0xffffffffu));
  imageStore(u_shadow_thick, p, uvec4(0u));
}
