// The reconstruction benchmark: allocation, visible list, fusion, empty-block removal and raycast
// per frame, timed per stage with StageTimer (CUDA events on the GPU). Goal on H100/H200:
// allocate + visible + fuse + raycast <= 0.5 ms per 640x480 frame at 5 mm voxels (median).
// One code path: ReconBench steps one frame at a time; bench_recon() runs a sequence through it,
// and `seamless bench recon` (src/app/bench_recon_cases.cpp) registers its step and report.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/timing.hpp"
#include "recon/volume.hpp"

namespace seamless {

struct ReconFrame {
  Image<float> depth;  // metres
  Image<uchar3> rgb;   // may be empty
  SE3 world_T_camera;  // ground truth or tracked
};

struct ReconBenchResult {
  int frames = 0;
  // Median milliseconds per frame of each stage ("allocate", "visible", "fuse", "remove_empty",
  // "raycast"; the dense grid has only "fuse" and "raycast") and of the whole frame ("frame").
  std::vector<std::pair<std::string, double>> median_ms;
  std::vector<StageTimer::Row> rows;  // every frame's stages, for timings.csv
  VolumeStats stats;                  // after the last frame
};

// A fresh volume of params.layout on device d and the frames (copied to d here, outside any
// timing), stepped one frame at a time.
class ReconBench {
 public:
  ReconBench(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params, Device d);
  // Integrates and raycasts the next frame (cycling through them), timing its stages and "frame".
  void step();
  // Forgets the frames timed so far (after a warm-up); the volume keeps what they fused.
  void reset_timing();
  // Frames timed since the last reset, their stage medians and rows, the volume's stats.
  ReconBenchResult result();
  // One line for `seamless bench recon`: "stage medians (ms): allocate ... ; blocks N, B bytes/block".
  std::string report();
  // Median over the timed frames of allocate + visible + fuse + raycast (ms): the 0.5 ms goal.
  double goal_stages_median_ms() const;
  std::size_t frame_count() const { return frames_.size(); }

 private:
  std::vector<ReconFrame> frames_;
  Intrinsics K_;
  Device device_;
  std::unique_ptr<Volume> volume_;
  RaycastMaps maps_;
  std::unique_ptr<StageTimer> timer_;
  std::int64_t next_ = 0, timed_ = 0;
};

// Runs frames once through a ReconBench; the first `warmup` frames are run but not reported.
ReconBenchResult bench_recon(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params,
                             Device d, int warmup = 2);

}  // namespace seamless
