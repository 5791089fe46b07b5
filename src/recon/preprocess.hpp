// Host side of depth preprocessing: owns the per-level images on one device and runs the kernels
// of kernels/recon/preprocess.hpp. Level 0 is full resolution.
#pragma once
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "recon/preprocess_params.hpp"

namespace seamless {

struct PyramidLevel {
  Intrinsics K;
  Image<float> depth;      // metres, filtered at level 0
  Image<float> intensity;  // [0,1], when the frame had colour
  Image<vec3> vertices;    // camera coordinates
  Image<vec3> normals;
};

class FramePyramid {
 public:
  FramePyramid(Device d, const Intrinsics& K, int levels);
  // raw_depth and intensity (optional) are full-resolution images on this pyramid's device.
  void build(const Image<float>& raw_depth, const Image<float>* intensity, const PreprocessParams& p);
  const PyramidLevel& level(int l) const { return levels_[l]; }
  PyramidLevel& mutable_level(int l) { return levels_[l]; }  // masking pixels out (dynamic pixels)
  int levels() const { return static_cast<int>(levels_.size()); }
  Device device() const { return device_; }

 private:
  Device device_;
  std::vector<PyramidLevel> levels_;
};

}  // namespace seamless
