// The host oracle of DeviceColliders (physics/depth_colliders.hpp): the depth camera's collider
// particles written plainly, point by point, on the host. The tests check it against exact
// geometry (colliders_test.cpp) and DeviceColliders against it (device_colliders_test.cpp).
#pragma once
#include <cstdint>
#include <vector>

#include "core/math.hpp"

namespace seamless {

// One frame's seen surface: a point per used pixel (world), the unit ray from the camera to it and
// the surface normal there (world; zero where the vertex map has none).
struct DepthSurface {
  std::vector<vec3> points, rays, normals;
};

// camera_vertices, camera_normals: vertex and normal maps (camera coordinates, row-major, z <= 0 =
// no reading, the zero vector = no normal), width x height; mask: empty (every pixel) or one byte
// per pixel (nonzero = use it).
DepthSurface depth_surface(const std::vector<vec3>& camera_vertices, const std::vector<vec3>& camera_normals, int width,
                           int height, const SE3& world_T_camera, const std::vector<std::uint8_t>& mask = {});

// Each surface point and, behind it along its ray, one more every `spacing` metres up to `thickness`.
std::vector<vec3> thicken(const std::vector<vec3>& points, const std::vector<vec3>& rays, float spacing,
                          float thickness);

// The colliders between two frames. A depth camera gives no correspondences, so each point's
// velocity is its displacement along the surface normal from the previous frame's nearest point
// within max_speed * dt (point to plane, as in ICP: exact for a surface moving along its normal
// whatever the pixels' positions on it; the motion along the surface, which pushes nothing, is
// not seen).
// The colliders then move with those velocities across the solver steps between the frames
// instead of jumping once a frame: a position-based contact turns a jump into the pushed particle's
// velocity over one step (a body walking at 1 m/s at 30 Hz would fling what it touches at
// 3.3 m/s with 0.01 s steps).
class MovingColliders {
 public:
  MovingColliders(float spacing, float thickness, float max_speed)
      : spacing_(spacing), thickness_(thickness), max_speed_(max_speed) {}
  // A new frame's surface, seen at simulation time t (after the previous frame's).
  void update(DepthSurface surface, double t);
  // The colliders at time t in [previous frame's time, this frame's]: each point moved back from
  // this frame's position by its velocity times (this frame's time - t).
  std::vector<vec3> at(double t) const;
  const std::vector<vec3>& velocities() const { return velocity_; }

 private:
  float spacing_, thickness_, max_speed_;
  DepthSurface last_;
  std::vector<vec3> velocity_;  // one per point of last_
  double time_ = 0.0;
  bool have_ = false;
};

}  // namespace seamless
