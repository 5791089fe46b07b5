// Pinhole camera helpers shared by the screen-space passes (x right, y down, z forward; see
// render/render_camera.hpp for the projection these invert).
uniform vec4 u_K;         // fx, fy, cx, cy in framebuffer pixels
uniform vec2 u_size;      // framebuffer width, height
uniform vec2 u_near_far;  // znear, zfar

// Image pixel (u right, v down) of window texel t: the same numbers as frag_pixel() gives for the
// fragment at t, so that the compute and fragment versions of a screen pass agree.
vec2 texel_pixel(ivec2 t) { return vec2(float(t.x), u_size.y - 1.0 - float(t.y)); }

#ifndef SEAMLESS_COMPUTE
// Image pixel (u right, v down) of this fragment (compute shaders have no fragment).
vec2 frag_pixel() { return vec2(gl_FragCoord.x - 0.5, u_size.y - gl_FragCoord.y - 0.5); }
#endif

// Ray through a pixel with z = 1, so that a point at depth z is z * pixel_ray(p).
vec3 pixel_ray(vec2 p) { return vec3((p.x - u_K.z) / u_K.x, (p.y - u_K.w) / u_K.y, 1.0); }

float window_depth(float z) {
  float n = u_near_far.x, f = u_near_far.y;
  float ndc = (f + n) / (f - n) - 2.0 * f * n / ((f - n) * z);
  return 0.5 * ndc + 0.5;
}

float eye_depth(float w) {
  float n = u_near_far.x, f = u_near_far.y;
  return -2.0 * f * n / ((f - n) * ((2.0 * w - 1.0) - (f + n) / (f - n)));
}

// The fluid's depth images (eye z, 0 = no fluid) carry in each depth's least significant mantissa
// bit whether the nearest splat there is a lone drop (splat.glsl, "Lone drops"), and in the next
// whether that drop lies flat on a surface (a sessile drop, "Lone drops at rest"); every pass that
// writes a surface depth clears both.
float with_drop_tag(float z, bool drop, bool flat_drop) {
  return uintBitsToFloat((floatBitsToUint(z) & ~3u) | (drop ? (flat_drop ? 3u : 1u) : 0u));
}
float with_drop_flag(float z, bool drop) { return with_drop_tag(z, drop, false); }
bool is_drop(float z) { return z > 0.0 && (floatBitsToUint(z) & 1u) != 0u; }
bool is_flat_drop(float z) { return z > 0.0 && (floatBitsToUint(z) & 3u) == 3u; }
