// Camera trajectories in the TUM RGB-D format: one pose a line, `timestamp tx ty tz qx qy qz qw`
// (world_T_camera: the camera's position and orientation in the world; unit quaternion, Hamilton
// convention, scalar last). Comment lines start with '#'. Used for ground truth, for the tracker's
// trajectory.txt and for evaluation (ATE/RPE).
#pragma once
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "core/math.hpp"

namespace seamless {

// Kept in double: timestamps are UNIX seconds (1.3e9) and evaluation compares millimetres.
struct TumPose {
  double timestamp = 0;
  double t[3] = {0, 0, 0};     // tx ty tz, metres
  double q[4] = {0, 0, 0, 1};  // qx qy qz qw

  SE3 se3() const;  // world_T_camera
  static TumPose from_se3(double timestamp, const SE3& world_T_camera);
};

using Trajectory = std::vector<TumPose>;

// Throws seamless::Error naming the file and line for a malformed line, a non-unit quaternion
// (|q| outside [0.9, 1.1]; within it q is normalised) or timestamps that go backwards.
Trajectory read_tum_trajectory(const std::string& path);
void write_tum_trajectory(const std::string& path, const Trajectory& trajectory);

// Pose at time t: linear interpolation of the translation and slerp of the rotation between the
// two samples around t. nullopt outside the trajectory or when those samples are more than
// max_gap seconds apart (motion-capture dropouts: interpolating across them would invent poses).
std::optional<TumPose> interpolate_pose(const Trajectory& trajectory, double t, double max_gap = 0.1);

// Appends poses to a TUM trajectory file as they come, under the name <path>.partial (flushed per
// line, so a crashed run keeps what it had), renamed to <path> when closed: a file under its own
// name was closed by its writer. Throws seamless::Error when the file cannot be created or written.
class TrajectoryWriter {
 public:
  explicit TrajectoryWriter(const std::string& path, const std::string& comment = "");
  ~TrajectoryWriter();
  TrajectoryWriter(const TrajectoryWriter&) = delete;
  TrajectoryWriter& operator=(const TrajectoryWriter&) = delete;
  void write(const TumPose& pose);
  void write(double timestamp, const SE3& world_T_camera) { write(TumPose::from_se3(timestamp, world_T_camera)); }
  // Renames the file to its name (the destructor does it too, logging a failure instead).
  void close();

 private:
  std::string path_;
  std::FILE* f_ = nullptr;
};

}  // namespace seamless
