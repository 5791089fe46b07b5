// Kernel family of the depth camera's collider particles (solver.dynamic_colliders;
// physics/depth_colliders.hpp says what they are and DeviceMovingColliders strings these together):
// the level's dynamic mask, the seen surface compacted in pixel order, each point's velocity from
// the previous frame's nearest point, and the thickened colliders at a time between two frames.
// The same values as the host code of physics/depth_colliders.cpp (depth_surface, MovingColliders),
// which stays as its reference.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// What DepthColliders::inside counts in one frame.
struct InsideCount {
  std::int64_t inside = 0;   // particles inside a seen person now
  std::int64_t resting = 0;  // of them, those inside for more than rest_frames frames in a row
};

template <Executor Exec> struct DepthColliders {
  // level(x, y) = 1 when any full-resolution pixel that the pyramid level's pixel averages is
  // nonzero (blocks of full.width / level.width x full.height / level.height pixels).
  static void level_mask(const Exec& ex, View2D<const std::uint8_t> full, View2D<std::uint8_t> level);
  // used[i] = 1 for a pixel with a reading (z > 0) and, where mask.data is not null, a nonzero
  // mask byte; else 0. offset: its exclusive scan (each used pixel's slot); returns the number used.
  static std::int64_t used_pixels(const Exec& ex, View2D<const vec3> vertices, View2D<const std::uint8_t> mask,
                                  int* used, int* offset);
  // The used pixels in pixel order (slot = offset[i], the exclusive scan of used): the point and
  // the camera's unit ray to it and the normal, in world coordinates.
  static void surface(const Exec& ex, View2D<const vec3> vertices, View2D<const vec3> normals, const int* used,
                      const int* offset, SE3 world_T_camera, vec3* points, vec3* rays, vec3* world_normals);
  // Keys of the cells of side r (floor(p / r), wrapped to 2^bits per axis) and identity indices.
  static void cell_keys(const Exec& ex, const vec3* p, std::int64_t n, float r, int bits, std::uint32_t* keys,
                        int* idx);
  // Each point's velocity from the nearest previous point within r (point to plane along the
  // previous point's normal, over dt; zero where none is that near). last_sorted: the previous
  // points' indices sorted by cell key (stable), start: the cells' ranges of them
  // (NeighbourGrid::cell_starts).
  static void velocities(const Exec& ex, const vec3* points, std::int64_t n, const vec3* last, const vec3* last_normals,
                         const int* last_sorted, const int* start, float r, int bits, float dt, vec3* velocity);
  // The colliders `back` seconds before the frame: each point moved back by velocity * back, then
  // layers + 1 particles along its ray every `spacing` metres (point i's at i * (layers + 1) + k).
  static void thickened(const Exec& ex, const vec3* points, const vec3* rays, const vec3* velocity, std::int64_t n,
                        float back, float spacing, int layers, vec3* out);
  // The colliders' check: particle i (world position p[i]) is inside a seen person when, in the
  // camera camera_T_world with the full-resolution intrinsics K of `mask`, its nearest pixel is
  // nonzero in the mask, the level pixel holding it (mask pixel / scale per axis) has a reading v,
  // and along the particle's ray it lies more than `margin` and less than `thickness` behind v's
  // depth. run[i]: the frames in a row it has been inside, this one included (0 when outside);
  // updated from the previous frame's value.
  static InsideCount inside(const Exec& ex, const vec3* p, std::int64_t n, SE3 camera_T_world, Intrinsics K,
                            View2D<const std::uint8_t> mask, View2D<const vec3> level_vertices, int scale, float margin,
                            float thickness, int rest_frames, int* run);
};

}  // namespace seamless::kernels
