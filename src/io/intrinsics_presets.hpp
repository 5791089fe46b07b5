// Camera intrinsics presets (TUM RGB-D benchmark calibrations, Kinect v1 default) and the choice
// of intrinsics from the `input.intrinsics` config section.
#pragma once
#include <string>

#include "core/camera.hpp"

namespace seamless {

struct IntrinsicsParams;

// "freiburg1", "freiburg2", "freiburg3", "kinect_v1". Throws seamless::Error for another name.
Intrinsics intrinsics_preset(const std::string& name);

// The preset named by p (or p's fx fy cx cy for "custom"); for "auto" the calibration file
// `<folder>/calibration.txt` when present (written by record()), else a 3x3 camera matrix in
// `camera-intrinsics.txt` or `intrinsics.K.txt` (frame folders; looked for in the folder, then in
// its parent, where 3DMatch and 7-Scenes keep one for all the scene's sequence folders), else the
// preset whose name the folder's name contains ("freiburg1" or "fr1", ...), else kinect_v1.
// origin (optional): where the values came from, for the log ("file '...'", "preset kinect_v1 ...").
Intrinsics resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder = "", std::string* origin = nullptr);

// The file names of a 3x3 camera matrix the auto preset looks for (in this order).
inline constexpr const char* kIntrinsicsMatrixFiles[] = {"camera-intrinsics.txt", "intrinsics.K.txt"};
// The first of kIntrinsicsMatrixFiles in `folder`, else in its parent; "" when there is none.
std::string find_intrinsics_matrix(const std::string& folder);

// A 3x3 camera matrix K = [fx s cx; 0 fy cy; 0 0 1], nine numbers (whitespace or commas between
// them, '#' comments). Throws an Error naming the file for another count, a bottom row that is not
// 0 0 1, a non-zero second-row first entry, non-positive focal lengths or a skew s (the kernels' pinhole
// has none). width and height are left at their defaults (the file does not say).
Intrinsics read_intrinsics_matrix(const std::string& path);

// One info line: what intrinsics `what` uses, and where they came from.
void log_intrinsics(const std::string& what, const Intrinsics& K, const std::string& origin);

// calibration.txt: one line `fx fy cx cy width height d0 d1 d2 d3 d4` (after '#' comments).
Intrinsics read_calibration(const std::string& path);
void write_calibration(const std::string& path, const Intrinsics& K);

}  // namespace seamless
