// Turns a splat's integer image into the R32F image the later passes read, and clears the integer
// image for the next frame (so no separate clear pass is needed). Depth: float bits, 0xffffffff =
// no fluid -> 0. Thickness: fixed point -> metres.
layout(local_size_x = 8, local_size_y = 8) in;
layout(r32ui, binding = 0) uniform uimage2D u_acc;
layout(r32f, binding = 1) uniform writeonly image2D u_out;
uniform bool u_depth_bits;
uniform float u_metres_per_unit;  // thickness: 1 / fixed-point units per metre

void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(p, imageSize(u_out)))) return;
  uint v = imageLoad(u_acc, p).r;
  const uint empty = 0xffffffffu;
  if (u_depth_bits) {
    imageStore(u_out, p, vec4(v == empty ? 0.0 : uintBitsToFloat(v)));
    imageStore(u_acc, p, uvec4(empty));
  } else {
    imageStore(u_out, p, vec4(float(v) * u_metres_per_unit));
    imageStore(u_acc, p, uvec4(0u));
  }
}
