// The Kinect's point of view (dissertation 4.3.1, without its hand-tuned field of view): the RGB
// image as background, and its registered depth written as this pixel's depth so that virtual
// objects behind the real surface fail the depth test. No reading (0) means nothing is there.
uniform sampler2D u_rgb;
uniform sampler2D u_depth;  // metres, registered to u_rgb

layout(location = 0) out vec4 o_color;

void main() {
  vec2 uv = (frag_pixel() + 0.5) / u_size;  // image rows run down, as uploaded
  o_color = vec4(texture(u_rgb, uv).rgb, 1.0);
  float z = texture(u_depth, uv).r;
  gl_FragDepth = z > 0.0 ? window_depth(clamp(z, u_near_far.x, u_near_far.y)) : 1.0;
}
