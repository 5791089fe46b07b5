#include "render_test_util.hpp"

#include <algorithm>
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

double box_form_factor(vec3 p, vec3 n, vec3 centre, vec3 half) {
  const double pi = 3.14159265358979;
  // The distance from p to the box bounds the integrand's scale: cells of at most a quarter of it.
  const vec3 out = vmax(vmax(p - centre - half, centre - half - p), vec3{0.f, 0.f, 0.f});
  const double dist = std::max(static_cast<double>(length(out)), 1e-4);
  const double size = 2.0 * std::max({half.x, half.y, half.z});
  const int cells = static_cast<int>(std::clamp(std::ceil(4.0 * size / dist), 4.0, 256.0));
  double f = 0.0;
  for (int a = 0; a < 3; ++a)
    for (int side = -1; side <= 1; side += 2) {
      const vec3 q = p - centre;
      if (side * (&q.x)[a] <= (&half.x)[a]) continue;  // p does not see this face
      const int i = (a + 1) % 3, j = (a + 2) % 3;
      const double hi = (&half.x)[i], hj = (&half.x)[j], dA = (2 * hi / cells) * (2 * hj / cells);
      for (int s = 0; s < cells; ++s)
        for (int t = 0; t < cells; ++t) {
          double x[3];
          x[a] = side * (&half.x)[a], x[i] = -hi + (s + 0.5) * 2 * hi / cells, x[j] = -hj + (t + 0.5) * 2 * hj / cells;
          const double d[3] = {x[0] - q.x, x[1] - q.y, x[2] - q.z};
          const double r2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
          // Only what lies above p's plane reaches it.
          const double cos_p = std::max(0.0, (n.x * d[0] + n.y * d[1] + n.z * d[2]) / std::sqrt(r2));
          const double cos_f = -side * d[a] / std::sqrt(r2);  // the face's outward normal is side e_a
          f += cos_p * cos_f / (pi * r2) * dA;
        }
    }
  return f;
}

}  // namespace seamless::test
