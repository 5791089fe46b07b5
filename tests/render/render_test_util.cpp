#include "render_test_util.hpp"

#include <cmath>

namespace seamless::test {

Mesh rectangle(float x0, float x1, float y0, float y1, float z, uchar3 color) {
  Mesh m;
  m.positions = {{x0, y0, z}, {x1, y0, z}, {x1, y1, z}, {x0, y1, z}};
  m.normals.assign(4, vec3{0.f, 0.f, -1.f});
  m.colors.assign(4, color);
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

Intrinsics intrinsics(float f, float cx, float cy, int w, int h) {
  Intrinsics K;
  K.fx = K.fy = f;
  K.cx = cx, K.cy = cy;
  K.width = w, K.height = h;
  return K;
}

RenderCamera camera(const Intrinsics& K, const SE3& world_T_camera) {
  RenderCamera c;
  c.K = K;
  c.world_T_camera = world_T_camera;
  c.znear = 0.05f, c.zfar = 30.f;
  return c;
}

// Rodrigues' formula.
mat3 rotation(vec3 axis, float angle) {
  const vec3 k = normalize(axis);
  const mat3 K = {{{0, -k.z, k.y}, {k.z, 0, -k.x}, {-k.y, k.x, 0}}};
  return mat3::identity() + K * std::sin(angle) + (K * K) * (1.f - std::cos(angle));
}

}  // namespace seamless::test
