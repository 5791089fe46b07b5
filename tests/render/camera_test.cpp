// The projection matrix reproduces the pinhole model exactly (no field-of-view approximation).
#include <cmath>

#include "render_test_util.hpp"

namespace seamless::test {
namespace {

vec4 mul(const Mat4& M, vec3 p) {
  vec4 r{};
  for (int i = 0; i < 4; ++i) (&r.x)[i] = M[i] * p.x + M[4 + i] * p.y + M[8 + i] * p.z + M[12 + i];
  return r;
}

// Window x of a pixel centre u is u + 0.5; window y of image row v is H - (v + 0.5).
TEST(RenderCamera, ProjectionMatchesPinhole) {
  const Intrinsics K = intrinsics(525.f, 319.5f, 239.5f, 640, 480);
  Intrinsics Ka = K;
  Ka.fy = 530.f, Ka.cx = 311.2f, Ka.cy = 247.9f;
  const Mat4 P = projection_matrix(Ka, 0.1f, 10.f);
  for (vec3 p : {vec3{0.3f, -0.2f, 1.5f}, vec3{-1.f, 0.7f, 4.f}, vec3{0.f, 0.f, 0.5f}}) {
    const vec4 c = mul(P, p);
    const vec2 uv = Ka.project(p);
    const float wx = (c.x / c.w * 0.5f + 0.5f) * 640.f, wy = (c.y / c.w * 0.5f + 0.5f) * 480.f;
    EXPECT_NEAR(wx, uv.x + 0.5f, 1e-3f);
    EXPECT_NEAR(wy, 480.f - (uv.y + 0.5f), 1e-3f);
    EXPECT_NEAR(window_to_depth(c.z / c.w * 0.5f + 0.5f, 0.1f, 10.f), p.z, 1e-4f * p.z);
  }
  EXPECT_NEAR(depth_to_window(0.1f, 0.1f, 10.f), 0.f, 1e-6f);
  EXPECT_NEAR(depth_to_window(10.f, 0.1f, 10.f), 1.f, 1e-6f);
}

TEST(RenderCamera, LookAtPutsTargetAtPrincipalPoint) {
  const RenderCamera c = RenderCamera::look_at({1.f, 2.f, -3.f}, {0.f, 0.5f, 0.f}, {0.f, 1.f, 0.f}, 60.f, 200, 100);
  const vec3 t = c.world_T_camera.inverse() * vec3{0.f, 0.5f, 0.f};
  EXPECT_NEAR(t.x, 0.f, 1e-5f);
  EXPECT_NEAR(t.y, 0.f, 1e-5f);
  EXPECT_GT(t.z, 0.f);
  // World up appears up in the image (negative camera y).
  const vec3 above = c.world_T_camera.inverse() * vec3{0.f, 1.5f, 0.f};
  EXPECT_LT(above.y, 0.f);
  EXPECT_NEAR(determinant(c.world_T_camera.R), 1.f, 1e-5f);
  // fov: the top edge of the image is 30 degrees above the axis.
  EXPECT_NEAR(c.K.fy, 50.f / std::tan(30.f * 3.14159265f / 180.f), 1e-3f);
}

TEST(RenderCamera, ScaledIntrinsicsKeepPixelCentres) {
  const Intrinsics K = intrinsics(525.f, 319.5f, 239.5f, 640, 480);
  const Intrinsics S = scale_intrinsics(K, 1280, 720);
  const vec3 p{0.2f, -0.1f, 2.f};
  const vec2 a = K.project(p), b = S.project(p);
  EXPECT_NEAR(b.x + 0.5f, (a.x + 0.5f) * 2.f, 1e-3f);
  EXPECT_NEAR(b.y + 0.5f, (a.y + 0.5f) * 1.5f, 1e-3f);
}

// render.zoom: the picked pixel lands on the image centre and image distances from it grow by the
// zoom factor (a longer lens about that ray); zoom 1 without a pixel leaves the camera unchanged.
TEST(RenderCamera, ZoomCentresThePickedPixel) {
  const Intrinsics K = intrinsics(517.3f, 318.6f, 255.3f, 640, 480);
  const Intrinsics Z = zoom_intrinsics(K, 2.f, {126.f, 343.f});
  for (vec3 p : {vec3{-0.7f, 0.3f, 2.7f}, vec3{0.1f, -0.2f, 1.f}, vec3{0.4f, 0.5f, 3.5f}}) {
    const vec2 a = K.project(p), b = Z.project(p);
    EXPECT_NEAR(b.x, 319.5f + 2.f * (a.x - 126.f), 1e-3f);
    EXPECT_NEAR(b.y, 239.5f + 2.f * (a.y - 343.f), 1e-3f);
  }
  const Intrinsics C = zoom_intrinsics(K, 3.f, {});  // about the image centre
  const vec2 c = C.project(K.unproject(319.5f, 239.5f, 2.f));
  EXPECT_NEAR(c.x, 319.5f, 1e-3f);
  EXPECT_NEAR(c.y, 239.5f, 1e-3f);
  const Intrinsics U = zoom_intrinsics(K, 1.f, {});
  EXPECT_EQ(U.fx, K.fx);
  EXPECT_EQ(U.cx, K.cx);
  EXPECT_EQ(U.cy, K.cy);
}

}  // namespace
}  // namespace seamless::test
