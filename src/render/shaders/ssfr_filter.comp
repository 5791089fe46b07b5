// SSFR smoothing as a compute pass: filter_at() per texel into an R32F image.
layout(r32f, binding = 0) uniform writeonly image2D u_dst;

void main() {
  ivec2 p;
  if (screen_texel(imageSize(u_dst), p)) imageStore(u_dst, p, vec4(filter_at(p)));
}
