// SSFR shading through the rasteriser: a full-screen triangle, composite_at() per fragment.
layout(location = 0) out vec4 o_color;
layout(location = 1) out vec4 o_reflect;
layout(location = 2) out vec4 o_refract;

void main() { composite_at(ivec2(gl_FragCoord.xy), o_color, o_reflect, o_refract); }
