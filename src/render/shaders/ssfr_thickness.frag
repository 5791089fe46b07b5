// SSFR thickness (van der Laan et al. 2009, section 4.3): the length of the pixel's ray inside
// each sphere, summed by additive blending over all particles (no depth test), cut at the scene.
uniform sampler2D u_scene_depth;
// Chords of the enlarged spheres summed over a lattice of one particle diameter overcount the
// path in fluid by their volume fraction pi s^3 / 6 (s: radius scale); this is its inverse.
uniform float u_thickness_scale;

layout(location = 0) out float o_thickness;  // metres

void main() {
  float z_in, z_out;
  if (!hit_sphere(z_in, z_out)) discard;
  // The pass may run at reduced resolution (render.thickness_downsample): sample the full-size
  // scene depth at this pixel's position.
  float z_scene = eye_depth(texture(u_scene_depth, gl_FragCoord.xy / u_size).r);
  float len = (min(z_out, z_scene) - z_in) * length(pixel_ray(frag_pixel()));
  if (len <= 0.0) discard;
  o_thickness = len * u_thickness_scale;
}
