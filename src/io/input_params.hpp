// Input section of an experiment (`input:` in the YAML): where RGB-D frames come from.
// Owned by the input layer; described by visit() (see core/params.hpp), loaded by src/config.
#pragma once
#include <cstdint>
#include <string>

#include "core/params.hpp"

namespace seamless {

// Camera intrinsics: a named preset, or `custom` with fx fy cx cy given here.
struct IntrinsicsParams {
  std::string preset = "freiburg1";
  float fx = 525.f, fy = 525.f, cx = 319.5f, cy = 239.5f;  // used when preset is custom
  int width = 640, height = 480;

  template <class V> void visit(V& v) {
    // TUM values from vision.in.tum.de/data/datasets/rgbd-dataset/file_formats; kinect_v1 is the
    // generic 525/319.5/239.5 set the TUM page gives for the default OpenNI calibration.
    v("preset", preset, "intrinsics preset (fx fy cx cy below are used only for custom)",
      Choices{"freiburg1", "freiburg2", "freiburg3", "kinect_v1", "custom"});
    v("fx", fx, "focal length x, pixels (custom only)", Range{1.0, 1e5});
    v("fy", fy, "focal length y, pixels (custom only)", Range{1.0, 1e5});
    v("cx", cx, "principal point x, pixels (custom only)", Range{-1e4, 1e4});
    v("cy", cy, "principal point y, pixels (custom only)", Range{-1e4, 1e4});
    v("width", width, "image width, pixels", Range{1, 16384});
    v("height", height, "image height, pixels", Range{1, 16384});
  }
};

// The built-in synthetic room (no data needed; ground-truth poses known exactly).
struct SyntheticParams {
  std::uint64_t seed = 1;
  bool noise = true;
  int frames = 120;
  std::string trajectory = "orbit";

  template <class V> void visit(V& v) {
    v("seed", seed, "random seed for noise and scene jitter");
    v("noise", noise, "add Kinect-like depth noise and dropouts");
    v("frames", frames, "number of frames to generate", Range{1, 1000000});
    v("trajectory", trajectory, "camera path name (see io/synthetic)");
  }
};

struct InputParams {
  std::string source = "synthetic";
  std::string path;                 // TUM folder for source: tum
  double depth_scale = 5000.0;      // TUM: 5000 units per metre
  IntrinsicsParams intrinsics;
  std::int64_t max_frames = 0;      // 0 = all
  std::int64_t first_frame = 0;
  bool skip_bad_frames = false;
  SyntheticParams synthetic;

  template <class V> void visit(V& v) {
    v("source", source, "frame source", Choices{"synthetic", "tum", "kinect"});
    v("path", path, "dataset folder (source: tum), e.g. rgbd_dataset_freiburg1_desk");
    v("depth_scale", depth_scale, "depth units per metre in the depth PNGs", Range{1.0, 1e6});
    v("intrinsics", intrinsics, "camera intrinsics");
    v("max_frames", max_frames, "stop after this many frames; 0 = all", Range{0, 1e12});
    v("first_frame", first_frame, "skip frames before this index", Range{0, 1e12});
    v("skip_bad_frames", skip_bad_frames, "skip unreadable frames with a warning instead of stopping");
    v("synthetic", synthetic, "synthetic room settings (source: synthetic)");
  }
};

}  // namespace seamless
