#include "io/kinect_source.hpp"

#include <libfreenect.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "core/error.hpp"
#include "io/intrinsics_presets.hpp"

namespace seamless {
namespace {

constexpr int kW = 640, kH = 480;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The accelerometer's axes are the camera's turned half a turn about z (see tum_source.cpp).
vec3 camera_accel(freenect_raw_tilt_state* s) {
  double x, y, z;
  freenect_get_mks_accel(s, &x, &y, &z);
  return {static_cast<float>(-x), static_cast<float>(-y), static_cast<float>(z)};
}

}  // namespace

KinectSource::KinectSource(const InputParams& params, bool pinned) : params_(params), pinned_(pinned) {
  const IntrinsicsChoice choice = resolve_intrinsics(params.intrinsics);
  if (choice.flip_x || choice.flip_y)
    throw ConfigError("input.intrinsics for a live Kinect has a negative focal length (" + choice.chosen +
                      "): a Kinect's images are not flipped; give its focal lengths as positive numbers");
  K_ = choice.K;
  if (K_.width != kW || K_.height != kH)
    throw ConfigError("input.intrinsics width/height must be 640x480 for a Kinect v1 (got " + std::to_string(K_.width) +
                      "x" + std::to_string(K_.height) + ")");
  if (freenect_init(&ctx_, nullptr) < 0)
    throw InputError("libfreenect could not initialise (is libusb working? try running as root or add the udev rules)");
  freenect_set_log_level(ctx_, FREENECT_LOG_WARNING);
  freenect_select_subdevices(ctx_, static_cast<freenect_device_flags>(FREENECT_DEVICE_MOTOR | FREENECT_DEVICE_CAMERA));
  int n = freenect_num_devices(ctx_);
  int index = params.kinect.device_index;
  if (n <= 0 || index >= n) {
    close();
    throw InputError("no Kinect v1 found at input.kinect.device_index " + std::to_string(index) + " (" +
                     std::to_string(n) +
                     " connected): plug it in (with its power supply), check `lsusb` for 045e:02ae and the udev rules, "
                     "or use input.source: tum / synthetic");
  }
  if (freenect_open_device(ctx_, &dev_, index) < 0) {
    close();
    throw InputError("could not open Kinect " + std::to_string(index) +
                     " (in use by another program, or no permission)");
  }
  freenect_set_user(dev_, this);
  freenect_set_depth_callback(dev_, &KinectSource::on_depth);
  freenect_set_video_callback(dev_, &KinectSource::on_video);
  // Debian's fakenect (libfreenect 0.5.3) knows only the 11-bit mode and asserts on any other; it
  // hands the recorded bytes over unchanged, and write_fakenect_dump() records registered
  // millimetres. So under fakenect we ask for the 11-bit mode and still read millimetres.
  replay_ = std::getenv("FAKENECT_PATH") != nullptr;
  freenect_depth_format depth_format = replay_ ? FREENECT_DEPTH_11BIT : FREENECT_DEPTH_REGISTERED;
  if (freenect_set_video_mode(dev_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB)) < 0 ||
      freenect_set_depth_mode(dev_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, depth_format)) < 0 ||
      freenect_start_video(dev_) < 0 || freenect_start_depth(dev_) < 0) {
    close();
    throw InputError("the Kinect refused the 640x480 RGB + registered depth modes");
  }
  thread_ = std::thread([this] { capture_loop(); });
}

KinectSource::~KinectSource() { close(); }

void KinectSource::close() noexcept {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (dev_) {
    freenect_stop_depth(dev_);
    freenect_stop_video(dev_);
    freenect_close_device(dev_);
    dev_ = nullptr;
  }
  if (ctx_) {
    freenect_shutdown(ctx_);
    ctx_ = nullptr;
  }
}

void KinectSource::capture_loop() {
  std::string reason = "stopped";
  auto last_tilt = std::chrono::steady_clock::now() - std::chrono::seconds(1);
  while (!stop_) {
    if (freenect_process_events(ctx_) < 0) {
      reason = "freenect_process_events failed (Kinect unplugged, or the end of a fakenect recording)";
      break;
    }
    // The accelerometer is a USB control transfer: poll it at ~10 Hz, not per frame.
    if (std::chrono::steady_clock::now() - last_tilt > std::chrono::milliseconds(100)) {
      last_tilt = std::chrono::steady_clock::now();
      freenect_update_tilt_state(dev_);  // the callbacks read the cached state
    }
  }
  std::lock_guard lock(mutex_);
  ended_ = true;
  end_reason_ = reason;
  ready_.notify_all();
}

void KinectSource::on_video(_freenect_device* dev, void* data, std::uint32_t) {
  auto* self = static_cast<KinectSource*>(freenect_get_user(dev));
  auto* bytes = static_cast<const std::uint8_t*>(data);
  self->latest_rgb_.assign(bytes, bytes + kW * kH * 3);
}

void KinectSource::on_depth(_freenect_device* dev, void* data, std::uint32_t) {
  auto* self = static_cast<KinectSource*>(freenect_get_user(dev));
  if (self->latest_rgb_.empty()) return;  // pair every depth frame with the latest colour frame
  Raw raw;
  raw.timestamp = now_seconds();
  auto* mm = static_cast<const std::uint16_t*>(data);
  raw.depth_mm.assign(mm, mm + kW * kH);
  raw.rgb = self->latest_rgb_;
  // The cached state (fakenect fills it from its recording). All-zero counts: no reading yet.
  freenect_raw_tilt_state* tilt = freenect_get_tilt_state(dev);
  raw.has_accel = tilt->accelerometer_x || tilt->accelerometer_y || tilt->accelerometer_z;
  raw.accel = camera_accel(tilt);
  self->push(std::move(raw));
}

void KinectSource::push(Raw&& raw) {
  std::lock_guard lock(mutex_);
  if (static_cast<int>(queue_.size()) >= params_.kinect.queue_size) {
    queue_.pop_front();  // drop the oldest: never block the USB thread, keep latency low
    ++dropped_;
  }
  queue_.push_back(std::move(raw));
  ready_.notify_one();
}

// A recording made by fakenect-record holds raw 11-bit disparities, where 2047 means no reading
// and 0 never occurs; registered millimetres use 0 for no reading.
void KinectSource::check_replay_is_millimetres(const std::vector<std::uint16_t>& depth) const {
  std::size_t zeros = 0, raw_invalid = 0;
  for (std::uint16_t v : depth) {
    zeros += v == 0;
    raw_invalid += v == 2047;
  }
  if (zeros == 0 && raw_invalid > 0)
    throw InputError(std::string("the fakenect recording in FAKENECT_PATH=") + std::getenv("FAKENECT_PATH") +
                     " holds raw 11-bit disparity (made by fakenect-record); seamless replays recordings of registered "
                     "millimetres written by write_fakenect_dump() (docs/INPUT.md)");
}

bool KinectSource::next(RgbdFrame& frame) {
  Raw raw;
  {
    std::unique_lock lock(mutex_);
    auto timeout = std::chrono::duration<double>(params_.kinect.timeout_s);
    if (!ready_.wait_for(lock, timeout, [&] { return !queue_.empty() || ended_; }))
      throw InputError("no frame from the Kinect for " + std::to_string(params_.kinect.timeout_s) +
                       " s (input.kinect.timeout_s): is it still connected and powered?");
    if (queue_.empty()) {
      if (delivered_ == 0) throw InputError("the Kinect stopped before its first frame: " + end_reason_);
      return false;
    }
    raw = std::move(queue_.front());
    queue_.pop_front();
  }
  if (replay_ && delivered_ == 0) check_replay_is_millimetres(raw.depth_mm);
  frame.index = delivered_++;
  frame.timestamp = raw.timestamp;
  frame.intrinsics = K_;
  reserve_frame_images(frame, kW, kH, pinned_);
  float* d = frame.depth.buffer().data();
  // FREENECT_DEPTH_NO_VALUE is 0: no reading stays 0.
  for (int i = 0; i < kW * kH; ++i) d[i] = raw.depth_mm[i] * 1e-3f;
  std::memcpy(frame.rgb.buffer().data(), raw.rgb.data(), raw.rgb.size());
  frame.accelerometer.reset();
  if (raw.has_accel) frame.accelerometer = raw.accel;
  frame.ground_truth.reset();
  return true;
}

}  // namespace seamless
