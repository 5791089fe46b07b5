// Helpers shared by the tracker tests: sources, ground-truth collection, ATE.
#pragma once
#include <unistd.h>

#include <filesystem>
#include <memory>
#include <string>

#include "eval/trajectory_eval.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "recon/tracker_sequence.hpp"

namespace seamless::test {

inline InputParams synthetic_input(int frames, bool noise = true) {
  InputParams p;
  p.source = InputSource::synthetic;
  p.synthetic.frames = frames;
  p.synthetic.noise = noise;
  return p;
}

inline std::string tum_rpy_dir() { return std::string(SEAMLESS_TEST_DATA) + "/tum_fr1_rpy_000-149"; }

inline InputParams tum_input(const std::string& dir) {
  InputParams p;
  p.source = InputSource::tum;
  p.path = dir;
  return p;
}

// A temporary output folder for one test, removed afterwards.
struct TmpOut {
  std::filesystem::path path;
  explicit TmpOut(const std::string& tag) {
    path = std::filesystem::temp_directory_path() / ("seamless_track_" + tag + "_" + std::to_string(::getpid()));
    std::filesystem::remove_all(path);
  }
  ~TmpOut() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
  std::string str() const { return path.string(); }
};

// Tracks a source and collects the ground truth the frames carry (same timestamps).
struct Tracked {
  TrackSequenceResult result;
  Trajectory gt;
};
inline Tracked track_with_gt(FrameSource& src, const TrackSequenceParams& p, Device d, const std::string& out,
                             Volume* volume = nullptr) {
  Tracked t;
  t.result = track_sequence(src, p, d, out, volume, [&](const RgbdFrame& f, const FrameRecord&) {
    if (f.ground_truth) t.gt.push_back(TumPose::from_se3(f.timestamp, *f.ground_truth));
  });
  return t;
}

}  // namespace seamless::test
