#include "render/render_camera.hpp"

#include <cmath>

#include "core/basis.hpp"

namespace seamless {
namespace {
constexpr float kDegToRad = 3.14159265358979f / 180.f;
}  // namespace

RenderCamera RenderCamera::from_fov(float fov_y_deg, int width, int height, float znear, float zfar) {
  RenderCamera c;
  const float f = 0.5f * static_cast<float>(height) / std::tan(0.5f * fov_y_deg * kDegToRad);
  c.K.fx = c.K.fy = f;
  c.K.cx = 0.5f * static_cast<float>(width) - 0.5f;
  c.K.cy = 0.5f * static_cast<float>(height) - 0.5f;
  c.K.width = width;
  c.K.height = height;
  c.znear = znear;
  c.zfar = zfar;
  return c;
}

RenderCamera RenderCamera::look_at(vec3 eye, vec3 target, vec3 up, float fov_y_deg, int width, int height, float znear,
                                   float zfar) {
  RenderCamera c = from_fov(fov_y_deg, width, height, znear, zfar);
  vec3 z = normalize(target - eye);
  vec3 x = normalize(cross(z, up));  // right = forward x up for y down (x right, y down, z forward)
  if (length2(x) == 0.f) x = normalize(cross(z, vec3{1.f, 0.f, 0.f}));
  vec3 y = cross(z, x);
  for (int r = 0; r < 3; ++r) {
    c.world_T_camera.R.m[r][0] = (&x.x)[r];
    c.world_T_camera.R.m[r][1] = (&y.x)[r];
    c.world_T_camera.R.m[r][2] = (&z.x)[r];
  }
  c.world_T_camera.t = eye;
  return c;
}

Intrinsics scale_intrinsics(const Intrinsics& K, int W, int H) {
  Intrinsics s = K;
  const float sx = static_cast<float>(W) / static_cast<float>(K.width);
  const float sy = static_cast<float>(H) / static_cast<float>(K.height);
  s.fx *= sx;
  s.fy *= sy;
  s.cx = (K.cx + 0.5f) * sx - 0.5f;
  s.cy = (K.cy + 0.5f) * sy - 0.5f;
  s.width = W;
  s.height = H;
  return s;
}

Intrinsics zoom_intrinsics(const Intrinsics& K, float zoom, const std::vector<float>& at) {
  const float u = at.size() == 2 ? at[0] : 0.5f * static_cast<float>(K.width - 1);
  const float v = at.size() == 2 ? at[1] : 0.5f * static_cast<float>(K.height - 1);
  Intrinsics z = K;
  z.fx *= zoom;
  z.fy *= zoom;
  z.cx = 0.5f * static_cast<float>(K.width - 1) - zoom * (u - K.cx);
  z.cy = 0.5f * static_cast<float>(K.height - 1) - zoom * (v - K.cy);
  return z;
}

Mat4 projection_matrix(const Intrinsics& K, float n, float f) {
  const float W = static_cast<float>(K.width), H = static_cast<float>(K.height);
  Mat4 P{};  // column-major: P[c * 4 + r]
  // x_ndc = (2 (u + 0.5) / W) - 1 with u = fx x/z + cx
  P[0] = 2.f * K.fx / W;
  P[8] = 2.f * (K.cx + 0.5f) / W - 1.f;
  // y_ndc = 1 - 2 (v + 0.5) / H with v = fy y/z + cy (image rows run down, window y up)
  P[5] = -2.f * K.fy / H;
  P[9] = 1.f - 2.f * (K.cy + 0.5f) / H;
  // z_ndc = A + B / z, -1 at n and +1 at f; w_clip = z
  P[10] = (f + n) / (f - n);
  P[14] = -2.f * f * n / (f - n);
  P[11] = 1.f;
  return P;
}

Mat4 model_matrix(const SE3& T, vec3 s) {
  Mat4 M{};
  const float sc[3] = {s.x, s.y, s.z};
  for (int c = 0; c < 3; ++c)
    for (int r = 0; r < 3; ++r) M[c * 4 + r] = T.R.m[r][c] * sc[c];
  M[12] = T.t.x;
  M[13] = T.t.y;
  M[14] = T.t.z;
  M[15] = 1.f;
  return M;
}

Mat4 view_matrix(const SE3& world_T_camera) { return model_matrix(world_T_camera.inverse()); }

float depth_to_window(float z, float n, float f) {
  const float ndc = (f + n) / (f - n) - 2.f * f * n / ((f - n) * z);
  return 0.5f * ndc + 0.5f;
}

float window_to_depth(float w, float n, float f) {
  const float ndc = 2.f * w - 1.f;
  return -2.f * f * n / ((f - n) * (ndc - (f + n) / (f - n)));
}

vec3 OrbitState::eye(vec3 up) const {
  // An orthonormal basis with `up` as the pole (e1 x e2 = -u); yaw about it, pitch above the horizon.
  vec3 u = normalize(up), e1, e2;
  orthonormal_basis(u, e1, e2);
  e2 = -e2;
  vec3 dir = (e1 * std::cos(yaw) + e2 * std::sin(yaw)) * std::cos(pitch) + u * std::sin(pitch);
  return target + dir * distance;
}

}  // namespace seamless
