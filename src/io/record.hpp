// Writes any frame source as a TUM RGB-D folder, so that every tool reads a recording (or the
// synthetic room) exactly like downloaded data.
#pragma once
#include <cstdint>
#include <string>

#include "io/frame_source.hpp"

namespace seamless {

struct RecordOptions {
  std::int64_t max_frames = 0;  // 0 = until the source ends
  double depth_scale = 5000.0;  // units per metre in the 16-bit depth PNGs (TUM: 5000)
};

// Creates out_dir (and rgb/, depth/) and writes rgb/<t>.png, depth/<t>.png, rgb.txt, depth.txt,
// associations.txt, calibration.txt (intrinsics), accelerometer.txt when the frames have readings
// and groundtruth.txt when they have poses. Depths beyond 65535 / depth_scale are written as 0.
// The lists are appended and flushed frame by frame, so a recording that is stopped at any point
// loads up to its last whole frame; Ctrl-C or SIGTERM (core/interrupt.hpp) ends it after the frame
// being written. Returns the number of frames written. Throws seamless::Error when a file cannot
// be written.
std::int64_t record(FrameSource& source, const std::string& out_dir, const RecordOptions& options = {});

}  // namespace seamless
