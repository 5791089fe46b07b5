// SSFR shading as a compute pass: composite_at() per texel into the three RGBA8 images of the
// composite framebuffer (colour, reflection, refraction).
layout(rgba8, binding = 0) uniform writeonly image2D u_color;
layout(rgba8, binding = 1) uniform writeonly image2D u_reflect;
layout(rgba8, binding = 2) uniform writeonly image2D u_refract;

void main() {
  ivec2 p;
  if (!screen_texel(imageSize(u_color), p)) return;
  vec4 c, rl, rr;
  composite_at(p, c, rl, rr);
  imageStore(u_color, p, c);
  imageStore(u_reflect, p, rl);
  imageStore(u_refract, p, rr);
}
