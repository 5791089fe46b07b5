// SSFR pass 1 (van der Laan et al. 2009, section 4.1): nearest sphere surface depth per pixel.
// Fragments behind the scene are dropped so that the fluid surface is the visible one.
uniform sampler2D u_scene_depth;  // window depth of the scene

layout(location = 0) out float o_depth;  // eye z, metres

void main() {
  float z_in, z_out;
  if (!hit_sphere(z_in, z_out)) discard;
  float z_scene = eye_depth(texelFetch(u_scene_depth, ivec2(gl_FragCoord.xy), 0).r);
  if (z_in >= z_scene) discard;
  o_depth = z_in;
  gl_FragDepth = window_depth(z_in);
}
