// A live Kinect v1 through libfreenect (only built when SEAMLESS_HAS_FREENECT): depth registered to
// the RGB camera, RGB 640x480, accelerometer. input.kinect.depth_mode raw (the default) reads the
// 11-bit disparity and registers it with the unit's calibration (freenect_copy_registration) through
// the same code as a fakenect-record folder (io/kinect_model.hpp); registered takes libfreenect's
// FREENECT_DEPTH_REGISTERED millimetres.
//
// libfreenect delivers frames through callbacks from freenect_process_events(), which runs on a
// capture thread owned by the source. Each depth frame waits for the next colour frame and takes
// whichever of it and the previous one is nearer in device time (kinect_next_colour_is_nearer), then
// goes onto a bounded queue; when the consumer is slower than 30 Hz the queue drops its oldest
// frame instead of blocking the capture (so the next frame is always recent) and counts the drop.
// Works unchanged under fakenect (a replay libfreenect, FAKENECT_PATH): it replays a fakenect-record
// folder's raw disparity (registered with its device.json) or a dump of registered millimetres
// written by write_fakenect_dump(); the first frame's values tell which.
#pragma once
#include <atomic>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "io/kinect_model.hpp"

struct _freenect_context;
struct _freenect_device;

namespace seamless {

class KinectSource : public FrameSource {
 public:
  // Opens device params.kinect.device_index and starts streaming. Throws seamless::Error when
  // libfreenect cannot start or no such Kinect is connected.
  // pinned: frames in page-locked host memory (for a GPU pipeline; make_source decides).
  explicit KinectSource(const InputParams& params, bool pinned = false);
  ~KinectSource() override;  // stops the streams and the capture thread, closes the device
  KinectSource(const KinectSource&) = delete;
  KinectSource& operator=(const KinectSource&) = delete;

  // Waits up to kinect.timeout_s for the next frame. False once the device stopped delivering
  // (after at least one frame); an error before the first frame throws.
  bool next(RgbdFrame& frame) override;
  std::string name() const override { return "kinect:" + std::to_string(params_.kinect.device_index); }
  Intrinsics intrinsics() const override { return K_; }
  std::int64_t skipped_frames() const override { return dropped_.load(); }
  std::int64_t dropped_frames() const { return dropped_.load(); }

 private:
  struct Raw {
    double timestamp = 0;
    std::vector<std::uint16_t> depth;  // as delivered: 11-bit disparity or millimetres
    std::vector<std::uint8_t> rgb;
    bool has_accel = false;
    vec3 accel{};
  };
  // A depth frame waiting for the colour frame after it.
  struct Pending {
    Raw raw;
    std::uint32_t ticks = 0, colour_before_ticks = 0;
  };
  static void on_depth(_freenect_device* dev, void* data, std::uint32_t timestamp);
  static void on_video(_freenect_device* dev, void* data, std::uint32_t timestamp);
  void capture_loop();
  void finish_pending();
  void push(Raw&& raw);
  void close() noexcept;
  KinectCalibration calibration() const;
  void make_registrar();
  void decide_replay_content(const std::vector<std::uint16_t>& depth);

  InputParams params_;
  bool pinned_ = false;  // frames in page-locked host memory
  Intrinsics K_;
  _freenect_context* ctx_ = nullptr;
  _freenect_device* dev_ = nullptr;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  std::atomic<std::int64_t> dropped_{0};
  bool replay_ = false;      // running under fakenect (FAKENECT_PATH set)
  bool raw_depth_ = true;    // frames hold 11-bit disparity (else millimetres)
  bool swap_bytes_ = false;  // a replayed recording stored its samples big-endian
  std::optional<KinectRegistrar> registrar_;
  // Capture thread only (callbacks run there).
  std::vector<std::uint8_t> latest_rgb_;
  std::uint32_t latest_rgb_ticks_ = 0;
  std::optional<Pending> pending_;
  // Shared with the consumer.
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<Raw> queue_;
  bool ended_ = false;
  std::string end_reason_;
  std::int64_t delivered_ = 0;
  std::int64_t discarded_ = 0;  // input.first_frame
};

// Writes frames of `source` as a fakenect recording (the format Debian's libfreenect-bin replays
// through FAKENECT_PATH): INDEX.txt listing a-<t>-<n>.dump (raw accelerometer state),
// r-<t>-<n>.ppm (RGB) and d-<t>-<n>.pgm (depth as the registered mode delivers it: millimetres,
// host byte order, since fakenect hands the bytes over unchanged). Returns the frames written.
std::int64_t write_fakenect_dump(FrameSource& source, const std::string& dir, std::int64_t max_frames = 0);

}  // namespace seamless
