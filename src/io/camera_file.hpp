// Camera files as other tools write them (input.intrinsics.file, docs/INPUT.md "Camera files"):
// which format is told by the content, not the name.
//   - ORB-SLAM / OpenCV cv::FileStorage YAML (`%YAML:1.0`): Camera.fx fy cx cy [k1 k2 p1 p2 k3]
//     [Camera.width height] (ORB-SLAM2; ORB-SLAM3's Camera1.fx ... too), or camera_matrix and
//     distortion_coefficients as !!opencv-matrix nodes (rows, cols, data) with image_width and
//     image_height (OpenCV's calibration sample; ROS camera_calibration_parsers writes the same keys);
//   - ROS sensor_msgs/CameraInfo as YAML (`rostopic echo -n1`, ROS 2's lower-case keys too): K
//     (9 numbers, row-major), D, width, height;
//   - Open3D's PinholeCameraIntrinsic JSON: width, height, intrinsic_matrix (9 numbers, column-major).
// Focal lengths keep the file's sign (ICL-NUIM's fy is -480); choose_intrinsics() turns a negative
// one into an image flip (intrinsics_presets.hpp).
#pragma once
#include <string>

#include "core/intrinsics.hpp"

namespace seamless {

struct CameraFile {
  Intrinsics K;           // width and height: the file's, else the defaults (has_size false)
  bool has_size = false;  // the file gave the image size
  std::string format;     // "ORB-SLAM YAML", "OpenCV YAML", "ROS camera_info YAML", "Open3D JSON"
};

// Reads `path`. Throws an InputError naming the file and what is missing or wrong: an unknown
// layout (naming the keys looked for), a missing key, a matrix with the wrong count of numbers, a
// camera matrix that is not [fx 0 cx; 0 fy cy; 0 0 1], a zero focal length, a distortion model
// other than OpenCV's radial-tangential (plumb_bob) with at most k1 k2 p1 p2 k3.
CameraFile read_camera_file(const std::string& path);

// K = [fx s cx; 0 fy cy; 0 0 1] given row-major: the pinhole it holds. `where` names the file (and
// key) in the InputError for a bottom row other than 0 0 1, a non-zero K[1][0], a zero focal length
// or a skew (the kernels' pinhole has none). Focal lengths may be negative.
Intrinsics intrinsics_from_matrix(const double (&k)[9], const std::string& where);

}  // namespace seamless
