// Camera intrinsics presets (TUM RGB-D benchmark calibrations, Kinect v1 default) and the choice
// of intrinsics from the `input.intrinsics` config section.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"

namespace seamless {

struct IntrinsicsParams;

// "freiburg1", "freiburg2", "freiburg3", "kinect_v1". Throws seamless::Error for another name.
Intrinsics intrinsics_preset(const std::string& name);

// What `input.intrinsics` gives for a source reading `folder` (empty for sources without one) and
// why: `chosen` is the preset's name, "custom", "calibration.txt" or the camera file's name;
// `generic` is set when preset auto found nothing that tells the camera in a folder and fell back
// to kinect_v1.
//
// A negative focal length (ICL-NUIM gives fy = -480: its image rows run against its camera's y
// axis) becomes a flip of that image axis: with the rows flipped, v' = (H - 1) - v =
// (-fy) y / z + (H - 1 - cy), an ordinary pinhole with fy' = -fy > 0 and cy' = H - 1 - cy that sees
// the same 3D points in the same camera frame, so poses and ground truth keep their meaning and
// every kernel keeps its positive focal lengths. K holds the flipped camera's (positive) values;
// the sources flip each image they read (flip_image) when flip_x / flip_y are set. Distortion
// coefficients stay as they are: the normalised coordinates (u - cx) / fx, (v - cy) / fy do not
// change under the flip.
struct IntrinsicsChoice {
  Intrinsics K;
  std::string chosen, reason;
  bool generic = false;
  bool flip_x = false, flip_y = false;  // the file's fx / fy were negative
};
// preset auto: `<folder>/calibration.txt` when present (written by record()), else a 3x3 camera
// matrix in `camera-intrinsics.txt` or `intrinsics.K.txt` (frame folders; looked for in the folder,
// then in its parent, where 3DMatch and 7-Scenes keep one for all of a scene's sequence folders),
// else the preset the folder's name names (camera_in_folder_name), else kinect_v1 (generic).
IntrinsicsChoice choose_intrinsics(const IntrinsicsParams& p, const std::string& folder = "");

// choose_intrinsics(p, folder), logged: which values, from where and why (and any flip); a warning
// when a folder got the generic set.
IntrinsicsChoice resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder = "");

// Mirrors a host image's columns (flip_x) and rows (flip_y), as IntrinsicsChoice describes.
template <class T> void flip_image(Image<T>& im, bool flip_x, bool flip_y) {
  T* d = im.buffer().data();
  const std::int64_t w = im.width(), h = im.height();
  if (flip_y)
    for (std::int64_t y = 0; y < h / 2; ++y) std::swap_ranges(d + y * w, d + (y + 1) * w, d + (h - 1 - y) * w);
  if (flip_x)
    for (std::int64_t y = 0; y < h; ++y) std::reverse(d + y * w, d + (y + 1) * w);
}

// The file names of a 3x3 camera matrix the auto preset looks for (in this order).
inline constexpr const char* kIntrinsicsMatrixFiles[] = {"camera-intrinsics.txt", "intrinsics.K.txt"};
// The first of kIntrinsicsMatrixFiles in `folder`, else in its parent; "" when there is none.
std::string find_intrinsics_matrix(const std::string& folder);

// A 3x3 camera matrix K = [fx s cx; 0 fy cy; 0 0 1], nine numbers (whitespace or commas between
// them, '#' comments). Throws an InputError naming the file for another count, a bottom row that
// is not 0 0 1, a non-zero second-row first entry, a focal length below one pixel in size or a
// skew s (the kernels' pinhole has none). Negative focal lengths are kept (IntrinsicsChoice). width and height are left
// at their defaults (the file does not say).
Intrinsics read_intrinsics_matrix(const std::string& path);

// The TUM camera a folder name names: "freiburg1" for "rgbd_dataset_freiburg1_desk" or
// "tum_fr1_rpy" (freiburg or fr, an optional _ or -, then 1, 2 or 3 and no further digit, at the
// start of a word), or "bonn" for the Bonn RGB-D Dynamic dataset's "rgbd_bonn_crowd" (bonn at the
// start of a word, no letter after it); "" when it names none or two different ones.
// scripts/compare_trackers applies the same rule to the TUM names.
std::string camera_in_folder_name(const std::string& name);

// "fx 517.3 fy 516.5 cx 318.6 cy 255.3, 640x480, distortion 0.2624 ..." for logs.
std::string describe_intrinsics(const Intrinsics& K);

// calibration.txt: one line `fx fy cx cy width height d0 d1 d2 d3 d4` (after '#' comments).
Intrinsics read_calibration(const std::string& path);
void write_calibration(const std::string& path, const Intrinsics& K);

}  // namespace seamless
