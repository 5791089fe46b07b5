// One RGB-D frame and the interface every frame source implements (TUM folder, synthetic room,
// Kinect v1 through libfreenect). See docs/INPUT.md.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "kernels/scene/movers.hpp"

namespace seamless {

struct InputParams;

struct RgbdFrame {
  std::int64_t index = 0;  // position in the source's sequence (after skipped frames)
  // Seconds: the time trajectories and ground truth are stamped with (TUM: the colour image's, the
  // first column of TUM's associations, which its evaluation tools expect; fakenect and a live
  // Kinect: the depth image's arrival; frame folders: number / fps).
  double timestamp = 0.0;
  Image<float> depth;     // host image, metres, 0 = no reading; registered to rgb
  Image<uchar3> rgb;      // host image, 8-bit R, G, B
  Intrinsics intrinsics;  // of depth and rgb (undistorted: dist is zero when images are)
  // Specific force measured by the accelerometer, m/s^2, in the camera frame (x right, y down,
  // z forward): at rest it points up, e.g. (0, -9.81, 0) for a level camera.
  std::optional<vec3> accelerometer;
  std::optional<SE3> ground_truth;  // world_T_camera when the source knows it
  // Ground truth of moving things (the synthetic room with input.synthetic.movers): the mover id
  // each pixel sees (0: the static room), and the movers' capsules in the ground truth's frame.
  Image<std::uint8_t> mover_mask;
  std::optional<kernels::movers::Scene> movers;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Fills `frame` with the next frame; false at the end of the sequence.
  virtual bool next(RgbdFrame& frame) = 0;
  // Number of frames the source will deliver, when known in advance.
  virtual std::optional<std::int64_t> size() const { return std::nullopt; }
  virtual std::string name() const = 0;
  // Intrinsics of the frames to come (known before the first frame).
  virtual Intrinsics intrinsics() const = 0;
  // Frames left out because they were unreadable (input.skip_bad_frames) or dropped by a full queue.
  virtual std::int64_t skipped_frames() const { return 0; }
};

// Builds the source `params.source` names. The synthetic room renders on `device` (CPU or CUDA);
// for CUDA, every source delivers its frames in page-locked host memory (a quarter of the upload
// time of ordinary memory, and the upload can be asynchronous).
std::unique_ptr<FrameSource> make_source(const InputParams& params, Device device = Device::CPU);

// Makes frame.depth and frame.rgb w x h host images, keeping their memory when it already fits, so
// that a source decoding frame after frame into the same RgbdFrame allocates once. pinned: in
// page-locked memory (Image::pinned_host), for frames that go to a GPU.
void reserve_frame_images(RgbdFrame& frame, int w, int h, bool pinned);

}  // namespace seamless
