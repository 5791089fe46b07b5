// SSFR normals through the rasteriser: a full-screen triangle, normal_at() per fragment.
layout(location = 0) out vec4 o_normal;  // eye space, w = 1 where there is fluid

void main() { o_normal = normal_at(ivec2(gl_FragCoord.xy)); }
