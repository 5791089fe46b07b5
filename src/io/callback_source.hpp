// Frames handed over by a program that embeds seamless (the Python module's frame source, a camera
// driver of the user's own): the program fills each frame, this source checks its size against
// the intrinsics and removes lens distortion as the TUM source does. See docs/PYTHON.md.
#pragma once
#include <functional>

#include "io/frame_source.hpp"

namespace seamless {

class CallbackSource : public FrameSource {
 public:
  // Fills frame.depth (metres, 0 = no reading) and frame.rgb as host images of the camera's size,
  // frame.timestamp and, when known, frame.accelerometer and frame.ground_truth; false at the end.
  using Fetch = std::function<bool(RgbdFrame& frame)>;

  // K: the camera of the frames as given (with its lens distortion, which is removed on input when
  // `undistort`); size: the number of frames when known; max_frames > 0 stops after that many.
  CallbackSource(Fetch fetch, const Intrinsics& K, bool undistort, std::optional<std::int64_t> size,
                 std::int64_t max_frames, std::string name);
  bool next(RgbdFrame& frame) override;
  std::optional<std::int64_t> size() const override { return size_; }
  std::string name() const override { return name_; }
  Intrinsics intrinsics() const override;

 private:
  Fetch fetch_;
  Intrinsics K_;  // as given
  bool undistort_ = false;
  std::optional<std::int64_t> size_;
  std::int64_t max_frames_ = 0, delivered_ = 0;
  std::string name_;
  RgbdFrame raw_;              // the frame as fetched, before undistortion
  Image<vec2> undistort_map_;  // where each undistorted pixel comes from
};

}  // namespace seamless
