// SSFR normals as a compute pass: normal_at() per texel into an RGBA16F image.
layout(rgba16f, binding = 0) uniform writeonly image2D u_dst;

void main() {
  ivec2 p;
  if (screen_texel(imageSize(u_dst), p)) imageStore(u_dst, p, normal_at(p));
}
