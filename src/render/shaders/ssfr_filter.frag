// SSFR smoothing through the rasteriser: a full-screen triangle, filter_at() per fragment.
layout(location = 0) out float o_value;

void main() { o_value = filter_at(ivec2(gl_FragCoord.xy)); }
