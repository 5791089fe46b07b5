// Shadow pass 1: the bounds of the particle casters in the light frame (shadow.glsl), reduced on
// the GPU so that the map fits the objects without a read-back: each invocation walks particles
// grid-stride, a work group combines its invocations in shared memory, and one invocation of each
// group merges the group's bounds into the 6 x 1 bounds image by atomic min / max. The host
// has written the rigid bodies' bounds (or "empty") there first.
layout(local_size_x = 256) in;
layout(std430, binding = 0) readonly buffer Positions { float b_pos[]; };  // x y z, tightly packed
layout(std430, binding = 1) readonly buffer Phases { uint b_phase[]; };
layout(r32i, binding = 0) uniform iimage2D u_bounds;
uniform uint u_count;
uniform uint u_phase_mask;  // particles with any of these phase flags cast shadows
uniform float u_pad;        // sphere radius: the bounds hold the spheres, not just their centres

shared int s_bounds[6];

void main() {
  uint l = gl_LocalInvocationIndex;
  if (l < 6u) s_bounds[l] = l < 3u ? 0x7fffffff : -0x7fffffff - 1;
  barrier();
  vec3 lo = vec3(1e30), hi = vec3(-1e30);
  uint stride = gl_NumWorkGroups.x * gl_WorkGroupSize.x;
  for (uint i = gl_GlobalInvocationID.x; i < u_count; i += stride) {
    if ((b_phase[i] & u_phase_mask) == 0u) continue;
    vec3 q = u_light_R * vec3(b_pos[3u * i], b_pos[3u * i + 1u], b_pos[3u * i + 2u]);
    lo = min(lo, q);
    hi = max(hi, q);
  }
  if (lo.x <= hi.x) {
    for (int k = 0; k < 3; ++k) {
      atomicMin(s_bounds[k], order_int(lo[k] - u_pad));
      atomicMax(s_bounds[k + 3], order_int(hi[k] + u_pad));
    }
  }
  barrier();
  if (l < 3u) imageAtomicMin(u_bounds, ivec2(int(l), 0), s_bounds[l]);
  else if (l < 6u) imageAtomicMax(u_bounds, ivec2(int(l), 0), s_bounds[l]);
}
