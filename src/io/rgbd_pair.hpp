// One RGB-D frame as the folder sources store it (TUM folders, frame folders): a 16-bit depth PNG
// and its registered colour image. Both sources read, check and decode a frame's pair here.
#pragma once
#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/error.hpp"
#include "core/intrinsics.hpp"

namespace seamless {

class DepthScaleCheck;

struct RawRgbdPair {
  Image<std::uint16_t> depth;  // raw units (input.depth_scale per metre)
  Image<uchar3> colour;
};

// Reads the pair (the colour as PNG or JPEG, by content), mirrors both images where the camera
// file's focal lengths were negative (flip_x, flip_y), and checks that the depth is K's size and
// the colour the depth's. InputErrors name the file and both sizes.
RawRgbdPair read_rgbd_pair(const std::string& depth_path, const std::string& colour_path, const Intrinsics& K,
                           bool flip_x, bool flip_y);

// Depth in metres from raw units into `out` (a host image of raw's size): 0 and 65535 mean no
// reading (7-Scenes writes 65535). With fill_gaps the one-pixel gaps are filled (through
// gap_scratch, allocated here when its size differs); otherwise the first frame warns when they
// would help. Then the median-depth and depth-scale checks, which throw naming depth_path.
void decode_depth(const Image<std::uint16_t>& raw, double scale, const std::string& depth_path, bool fill_gaps,
                  bool first_frame, Image<float>& gap_scratch, DepthScaleCheck& scale_check, Image<float>& out);

// Keeps the folder's frames from first_frame on, at most max_frames of them (0: all); none left
// is an InputError naming the folder.
template <class Frame>
void select_frames(std::vector<Frame>& frames, std::int64_t first_frame, std::int64_t max_frames,
                   const std::string& folder) {
  const auto first = static_cast<std::size_t>(std::min<std::int64_t>(first_frame, std::ssize(frames)));
  frames.erase(frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(first));
  if (max_frames > 0 && frames.size() > static_cast<std::size_t>(max_frames))
    frames.resize(static_cast<std::size_t>(max_frames));
  if (frames.empty())
    throw InputError("input.first_frame " + std::to_string(first_frame) + " is past the end of '" + folder + "'");
}

}  // namespace seamless
