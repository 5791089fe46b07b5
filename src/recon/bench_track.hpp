// The tracking benchmark (`seamless bench track`, wired by the app): callables that each run one
// timed unit on prepared device data, for the app's runner (warm-up, repetitions, measure_ms).
// Goal on H100/H200 at 640x480: ICP (3 levels, 10/5/4 iterations) <= 0.3 ms median; the whole
// frame (upload, preprocess, track, fuse, raycast) <= 0.6 ms. One 6x6 download per Gauss-Newton
// iteration is inherent; everything else stays on the device.
#pragma once
#include <functional>
#include <string>
#include <vector>

#include "core/device.hpp"

namespace seamless {

struct TrackBenchCase {
  std::string name;            // e.g. "icp_640x480"
  std::function<void()> step;  // one timed call
  std::string detail;          // what one call does
};

// Cases: icp_640x480 and rgbd_640x480 (frame-to-frame alignment of two frames of the input, from
// the identity, 10/5/4 iterations) and frame_640x480 (TrackingSession::process of frame-to-model
// ICP with a 5 mm voxel-hashed volume: upload, preprocess, track, fuse, raycast). Input: the first
// frames of the TUM folder data_dir, or of the synthetic room when data_dir is empty.
std::vector<TrackBenchCase> make_track_bench(Device device, const std::string& data_dir = "");

}  // namespace seamless
