// World up / gravity for the tracker and the physics: from the accelerometer where there is one
// (Kinect v1, TUM), otherwise from the dominant horizontal plane (floor or table top: both are
// perpendicular to gravity). The world frame of a tracked sequence is then rotated so that gravity
// is world -y, the convention of solver.gravity (0, -9.81, 0).
#pragma once
#include <optional>
#include <string>

#include "core/math.hpp"
#include "recon/preprocess.hpp"
#include "recon/tracker_params.hpp"

namespace seamless {

struct GravityEstimate {
  vec3 down{0.f, 1.f, 0.f};     // unit vector along gravity in the camera frame it was estimated in
  std::string source = "none";  // accelerometer | floor | fixed | none
  bool found = false;           // false: the source asked for had nothing; down is the camera's +y
  double support = 0;           // floor: fraction of the level's valid pixels on the plane
};

// The dominant plane of the frame whose normal is within 60 degrees of the camera's up (-y: a
// hand-held camera is roughly upright) and that lies below the camera. Deterministic RANSAC over
// the coarsest pyramid level, refined by a least-squares fit of its inliers.
GravityEstimate floor_plane_gravity(const FramePyramid& frame);

// tracker.gravity: auto (accelerometer if present, else floor), accelerometer, floor, fixed
// (tracker.fixed_gravity), none. `accelerometer` is the specific force in the camera frame (it
// points up at rest), as RgbdFrame carries it.
GravityEstimate estimate_gravity(const TrackerParams& p, const std::optional<vec3>& accelerometer,
                                 const FramePyramid& frame);

// world_T_camera for a camera at the origin whose gravity direction is `down` (camera frame): the
// world's -y is down, and the camera's viewing direction, projected on the horizontal, is world +z
// (so a level camera keeps its heading: its x becomes world -x and its y, which points down, world -y).
SE3 gravity_aligned_pose(vec3 down);

}  // namespace seamless
