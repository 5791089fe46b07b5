// The Kinect's point of view (dissertation 4.3.1, without its hand-tuned field of view): the RGB
// image as background, and its registered depth written as this pixel's depth so that virtual
// objects behind the real surface fail the depth test. No reading (0) means nothing is there.
// The same depth places the real surface in the world (unprojected with the intrinsics, moved by
// the tracked pose), where the virtual objects' shadows darken it (shadow.glsl). Where there is no
// reading but the ray meets a surface the camera did not measure (Renderer::set_unmeasured_planes),
// that surface is there instead.
uniform sampler2D u_rgb;
uniform sampler2D u_depth;  // metres, registered to u_rgb
uniform mat4 u_world_T_camera;
uniform vec4 u_crop;        // the part of the image the frame shows: x, y, width, height (image pixels)
uniform vec2 u_image_size;  // of u_rgb and u_depth
uniform int u_plane_count;
uniform vec4 u_planes[4];   // n . x = w in the world: (n, w)

layout(location = 0) out vec4 o_color;

// Camera depth at which pixel px's ray meets the nearest of the unmeasured planes in front of the
// camera (between the near and far planes), or 0 where it meets none.
float unmeasured_depth(vec2 px) {
  vec3 o = u_world_T_camera[3].xyz;
  vec3 d = mat3(u_world_T_camera) * pixel_ray(px);  // world displacement per metre of camera depth
  float best = 0.0;
  for (int i = 0; i < u_plane_count; ++i) {
    float nd = dot(u_planes[i].xyz, d);
    if (abs(nd) < 1e-6) continue;  // the ray runs along the plane
    float t = (u_planes[i].w - dot(u_planes[i].xyz, o)) / nd;
    if (t > u_near_far.x && t < u_near_far.y && (best == 0.0 || t < best)) best = t;
  }
  return best;
}

// Texture coordinates in the image of frame pixel px: the framebuffer covers the crop
// (scale_intrinsics: pixel edges map to pixel edges); image rows run down, as uploaded.
vec2 image_uv(vec2 px) { return (u_crop.xy + (px + 0.5) * u_crop.zw / u_size) / u_image_size; }

// Camera depth of the real surface at frame pixel px: recorded, else an unmeasured plane's, else 0.
float surface_depth(vec2 px) {
  float z = texture(u_depth, image_uv(px)).r;
  return z > 0.0 ? z : unmeasured_depth(px);
}

// The real surface's world normal at px, from the surface points kNormalStep pixels to each side
// (a baseline over the Kinect's depth steps), turned towards the camera; (0, 0, 0) where a side
// has no depth.
const float kNormalStep = 3.0;
vec3 surface_normal(vec2 px) {
  float zr = surface_depth(px + vec2(kNormalStep, 0.0)), zl = surface_depth(px - vec2(kNormalStep, 0.0));
  float zd = surface_depth(px + vec2(0.0, kNormalStep)), zu = surface_depth(px - vec2(0.0, kNormalStep));
  if (zr <= 0.0 || zl <= 0.0 || zd <= 0.0 || zu <= 0.0) return vec3(0.0);
  vec3 dx = zr * pixel_ray(px + vec2(kNormalStep, 0.0)) - zl * pixel_ray(px - vec2(kNormalStep, 0.0));
  vec3 dy = zd * pixel_ray(px + vec2(0.0, kNormalStep)) - zu * pixel_ray(px - vec2(0.0, kNormalStep));
  vec3 n = cross(dx, dy);
  if (dot(n, n) <= 0.0) return vec3(0.0);
  n = normalize(n);
  if (dot(n, pixel_ray(px)) > 0.0) n = -n;  // towards the camera
  return mat3(u_world_T_camera) * n;
}

void main() {
  vec2 px = frag_pixel();
  vec3 rgb = texture(u_rgb, image_uv(px)).rgb;
  float z = surface_depth(px);
  if (z > 0.0) {
    vec3 world = (u_world_T_camera * vec4(z * pixel_ray(px), 1.0)).xyz;
    float occluded = 0.0;
    if (u_occluder_count > 0) {  // the normal's four reads only where a body can occlude
      vec3 n = surface_normal(px);
      if (dot(n, n) > 0.0) occluded = occluded_share(world, n);
    }
    rgb = shadowed_srgb(rgb, shadow_light(world, vec3(0.0), gl_FragCoord.xy), occluded);
  }
  o_color = vec4(rgb, 1.0);
  gl_FragDepth = z > 0.0 ? window_depth(clamp(z, u_near_far.x, u_near_far.y)) : 1.0;
}
