// The reconstruction benchmark (`seamless bench recon`, wired by the app): allocation, visible
// list, fusion, empty-block removal and raycast per frame, timed per stage with StageTimer (CUDA
// events on the GPU). Goal on H100/H200: allocate + visible + fuse + raycast <= 0.5 ms per
// 640x480 frame at 5 mm voxels (median).
#pragma once
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/camera.hpp"
#include "core/timing.hpp"
#include "recon/volume.hpp"

namespace seamless {

struct ReconFrame {
  Image<float> depth;   // metres
  Image<uchar3> rgb;    // may be empty
  SE3 world_T_camera;   // ground truth or tracked
};

struct ReconBenchResult {
  int frames = 0;
  // Median milliseconds per frame of each stage ("allocate", "visible", "fuse", "remove_empty",
  // "raycast"; the dense grid has only "fuse" and "raycast") and of the whole frame ("frame").
  std::vector<std::pair<std::string, double>> median_ms;
  std::vector<StageTimer::Row> rows;  // every frame's stages, for timings.csv
  VolumeStats stats;                  // after the last frame
};

// Runs frames through a fresh volume of params.layout on device d (frames are copied to d first,
// outside the timing). The first `warmup` frames are run but not reported.
ReconBenchResult bench_recon(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params,
                             Device d, int warmup = 2);

}  // namespace seamless
