// SSFR pass 1 (van der Laan et al. 2009, section 4.1): nearest sphere surface depth per pixel.
// Fragments behind the scene are dropped so that the fluid surface is the visible one.
uniform sampler2D u_scene_depth;  // window depth of the scene
uniform bool u_test_scene;        // false when the depth buffer already holds the scene (prepass)

#ifdef GL_ARB_conservative_depth
layout(depth_greater) out float gl_FragDepth;  // the sphere lies behind its sprite (sphere.vert)
#endif

layout(location = 0) out float o_depth;  // eye z, metres

void main() {
  float z_in, z_out;
  if (!hit_sphere(z_in, z_out)) discard;
  if (u_test_scene && z_in >= eye_depth(texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r)) discard;
  o_depth = with_drop_flag(z_in, false);  // sprites are spheres: no particle is a lone drop
  gl_FragDepth = window_depth(z_in);
}
