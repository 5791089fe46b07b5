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
// `<folder>/calibration.txt` when present (written by record()), else the preset whose name the
// folder's name contains ("freiburg1" or "fr1", ...), else kinect_v1.
Intrinsics resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder = "");

// calibration.txt: one line `fx fy cx cy width height d0 d1 d2 d3 d4` (after '#' comments).
Intrinsics read_calibration(const std::string& path);
void write_calibration(const std::string& path, const Intrinsics& K);

}  // namespace seamless
