// The fluid depth splat's occluders (ssfr_depth_splat.comp, render.fluid_occluders): the list of
// the fluid particles whose anisotropic kernel found them at the fluid's surface, the offset of
// their neighbours' weighted mean at least u_occluder_offset h (kernels/physics/anisotropy.hpp;
// lone drops have 1). Any list gives the same depth image; this one is what covers the fluid
// from outside. Appended per work group (one global atomic a group); the order is arbitrary.
layout(std430, binding = 3) buffer Occluders {
  uint b_occluder_count;
  uint b_skipped;
  uint b_occluder[];
};
uniform float u_occluder_offset;

shared uint s_count, s_base;

void main() {
  uint i = particle_index();
  bool occluder = i < u_count && (u_phase_mask == 0u || (b_phase[i] & u_phase_mask) != 0u) &&
                  b_ell[3u * i + 2u].w >= u_occluder_offset;
  if (gl_LocalInvocationIndex == 0u) s_count = 0u;
  barrier();
  uint k = occluder ? atomicAdd(s_count, 1u) : 0u;
  barrier();
  if (gl_LocalInvocationIndex == 0u) s_base = s_count > 0u ? atomicAdd(b_occluder_count, s_count) : 0u;
  barrier();
  if (occluder) b_occluder[s_base + k] = i;
}
