// The renderer's camera: the pinhole model of the Kinect (core/intrinsics.hpp; x right, y down,
// z forward) with a pose, so that the Kinect view projects with the sensor's exact intrinsics
// and any free camera is the same model with intrinsics made from a field of view.
#pragma once
#include <array>
#include <vector>

#include "core/intrinsics.hpp"
#include "core/math.hpp"

namespace seamless {

using Mat4 = std::array<float, 16>;  // column-major, as OpenGL takes it

struct RenderCamera {
  Intrinsics K;  // pixels of the framebuffer (see scaled_to)
  SE3 world_T_camera = SE3::identity();
  float znear = 0.05f, zfar = 30.f;

  // Square pixels, principal point in the centre, vertical field of view in degrees.
  static RenderCamera from_fov(float fov_y_deg, int width, int height, float znear, float zfar);
  // Camera at `eye` looking at `target`; `up` is the world's up (y down in the image).
  static RenderCamera look_at(vec3 eye, vec3 target, vec3 up, float fov_y_deg, int width, int height,
                              float znear = 0.05f, float zfar = 30.f);
  vec3 position() const { return world_T_camera.t; }
};

// Intrinsics of an image of w x h pixels resampled to W x H (pixel centres at integers).
Intrinsics scale_intrinsics(const Intrinsics& K, int W, int H);

// The same camera magnified `zoom` times about pixel `at` ([u, v] of K's image; empty: the image
// centre), which lands on the image centre: a crop of the view, as a longer lens would see it.
// Focal lengths times zoom; the principal point moves so that the ray through `at` projects to
// the centre: u' = cx' + zoom (u - cx) = (w - 1) / 2.
Intrinsics zoom_intrinsics(const Intrinsics& K, float zoom, const std::vector<float>& at);

// OpenGL clip transform of a pinhole camera: pixel u = fx x/z + cx lands on window x = u + 0.5
// and image row v on window y = H - (v + 0.5), so image row 0 is the top of the picture.
// Depth maps z in [znear, zfar] to NDC [-1, 1] like a standard perspective matrix.
Mat4 projection_matrix(const Intrinsics& K, float znear, float zfar);
// camera_T_world as a 4x4 matrix.
Mat4 view_matrix(const SE3& world_T_camera);
Mat4 model_matrix(const SE3& world_T_object, vec3 scale = {1.f, 1.f, 1.f});

// Window depth (0..1) of camera z, and back: the fluid and Kinect passes write and read it.
float depth_to_window(float z, float znear, float zfar);
float window_to_depth(float w, float znear, float zfar);

// Orbit camera of the window front end: yaw/pitch about a target at a distance.
struct OrbitState {
  vec3 target{0.f, 0.f, 0.f};
  float yaw = 0.f, pitch = 0.3f, distance = 3.f;  // radians, metres
  vec3 eye(vec3 up) const;
};

}  // namespace seamless
