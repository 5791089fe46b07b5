#include "io/kinect_source.hpp"

#include <dlfcn.h>
#include <libfreenect.h>
#include <libfreenect_registration.h>
#include <spdlog/spdlog.h>

#include <bit>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>

#include "core/error.hpp"
#include "io/fakenect_source.hpp"
#include "io/intrinsics_presets.hpp"

namespace seamless {
namespace {

constexpr int kW = 640, kH = 480;

double now_seconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

// The unit's calibration as libfreenect read it from the device. Looked up at run time: fakenect's
// replay library (Debian's libfreenect 0.5) has no freenect_copy_registration.
std::optional<KinectCalibration> device_calibration(freenect_device* dev) {
  using Copy = freenect_registration (*)(freenect_device*);
  using Destroy = int (*)(freenect_registration*);
  auto copy = reinterpret_cast<Copy>(dlsym(RTLD_DEFAULT, "freenect_copy_registration"));
  auto destroy = reinterpret_cast<Destroy>(dlsym(RTLD_DEFAULT, "freenect_destroy_registration"));
  if (!copy || !destroy) return std::nullopt;
  freenect_registration r = copy(dev);
  const freenect_reg_info& i = r.reg_info;
  KinectCalibration c;
  c.ax = i.ax, c.bx = i.bx, c.cx = i.cx, c.dx = i.dx, c.ay = i.ay, c.by = i.by, c.cy = i.cy, c.dy = i.dy;
  c.dx_start = i.dx_start, c.dy_start = i.dy_start;
  c.dxdx_start = i.dxdx_start, c.dxdy_start = i.dxdy_start, c.dydx_start = i.dydx_start, c.dydy_start = i.dydy_start;
  c.dxdxdx_start = i.dxdxdx_start, c.dydxdx_start = i.dydxdx_start, c.dxdxdy_start = i.dxdxdy_start;
  c.dydxdy_start = i.dydxdy_start, c.dydydx_start = i.dydydx_start, c.dydydy_start = i.dydydy_start;
  c.pad_start_lines = r.reg_pad_info.start_lines;
  c.emitter_cm = r.zero_plane_info.dcmos_emitter_dist;
  c.rgb_cm = r.zero_plane_info.dcmos_rcmos_dist;
  c.reference_distance = r.zero_plane_info.reference_distance;
  c.reference_pixel_size = r.zero_plane_info.reference_pixel_size;
  c.const_shift = r.const_shift;
  c.origin = "the device (freenect_copy_registration)";
  destroy(&r);
  if (!(c.reference_distance > 0 && c.reference_pixel_size > 0 && c.emitter_cm > 0)) return std::nullopt;
  return c;
}

vec3 camera_accel(const freenect_raw_tilt_state* s) {
  return kinect_accel_to_camera(s->accelerometer_x, s->accelerometer_y, s->accelerometer_z);
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
  // hands the recorded bytes over unchanged: raw disparity from fakenect-record, registered
  // millimetres from write_fakenect_dump(). So under fakenect we ask for the 11-bit mode and tell
  // the content by the first frame's values.
  replay_ = std::getenv("FAKENECT_PATH") != nullptr;
  raw_depth_ = replay_ || params.kinect.depth_mode == KinectDepthMode::raw;
  if (raw_depth_ && !replay_) make_registrar();  // a replay: once its first frame tells its content
  freenect_depth_format depth_format = raw_depth_ ? FREENECT_DEPTH_11BIT : FREENECT_DEPTH_REGISTERED;
  if (freenect_set_video_mode(dev_, freenect_find_video_mode(FREENECT_RESOLUTION_MEDIUM, FREENECT_VIDEO_RGB)) < 0 ||
      freenect_set_depth_mode(dev_, freenect_find_depth_mode(FREENECT_RESOLUTION_MEDIUM, depth_format)) < 0 ||
      freenect_start_video(dev_) < 0 || freenect_start_depth(dev_) < 0) {
    close();
    throw InputError(std::string("the Kinect refused the 640x480 RGB + ") + (raw_depth_ ? "11-bit" : "registered") +
                     " depth modes");
  }
  thread_ = std::thread([this] { capture_loop(); });
}

KinectSource::~KinectSource() { close(); }

void KinectSource::make_registrar() {
  const KinectCalibration cal = calibration();
  registrar_.emplace(cal);
  spdlog::info("Kinect depth: raw disparity registered to colour by seamless, calibration from {}", cal.origin);
}

KinectCalibration KinectSource::calibration() const {
  if (!params_.kinect.calibration.empty()) return read_kinect_device_json(params_.kinect.calibration);
  if (!replay_)
    if (auto c = device_calibration(dev_)) return *c;
  // A replay: the recording's device.json (what newer fakenect versions read as well).
  return kinect_calibration_for("", replay_ ? std::getenv("FAKENECT_PATH") : "");
}

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
  finish_pending();
  std::lock_guard lock(mutex_);
  ended_ = true;
  end_reason_ = reason;
  ready_.notify_all();
}

void KinectSource::on_video(_freenect_device* dev, void* data, std::uint32_t timestamp) {
  auto* self = static_cast<KinectSource*>(freenect_get_user(dev));
  auto* bytes = static_cast<const std::uint8_t*>(data);
  if (self->pending_) {
    Pending& p = *self->pending_;
    if (p.raw.rgb.empty() || kinect_next_colour_is_nearer(p.ticks, p.colour_before_ticks, timestamp))
      p.raw.rgb.assign(bytes, bytes + kW * kH * 3);
    self->finish_pending();
  }
  self->latest_rgb_.assign(bytes, bytes + kW * kH * 3);
  self->latest_rgb_ticks_ = timestamp;
}

void KinectSource::on_depth(_freenect_device* dev, void* data, std::uint32_t timestamp) {
  auto* self = static_cast<KinectSource*>(freenect_get_user(dev));
  self->finish_pending();  // no colour frame came between two depth frames: the one before it
  Pending p;
  p.raw.timestamp = now_seconds();
  auto* samples = static_cast<const std::uint16_t*>(data);
  p.raw.depth.assign(samples, samples + kW * kH);
  p.raw.rgb = self->latest_rgb_;
  p.ticks = timestamp;
  p.colour_before_ticks = self->latest_rgb_ticks_;
  self->pending_ = std::move(p);
}

// Sends the waiting depth frame on with the accelerometer state received so far; dropped when no
// colour frame has arrived yet (the stream's start).
void KinectSource::finish_pending() {
  if (!pending_) return;
  Raw raw = std::move(pending_->raw);
  pending_.reset();
  if (raw.rgb.empty()) return;
  // The cached state (fakenect fills it from its recording). All-zero counts: no reading yet.
  const freenect_raw_tilt_state* tilt = freenect_get_tilt_state(dev_);
  raw.has_accel = tilt->accelerometer_x || tilt->accelerometer_y || tilt->accelerometer_z;
  raw.accel = camera_accel(tilt);
  push(std::move(raw));
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

// A recording made by fakenect-record holds raw 11-bit disparities (in either byte order), where
// 2047 means no reading and 0 never occurs; registered millimetres use 0 for no reading.
void KinectSource::decide_replay_content(const std::vector<std::uint16_t>& depth) {
  std::size_t zeros = 0;
  for (std::uint16_t v : depth) zeros += v == 0;
  const std::string where = std::string("fakenect recording in FAKENECT_PATH=") + std::getenv("FAKENECT_PATH");
  if (zeros > 0) {
    raw_depth_ = false;
    spdlog::info("{}: registered millimetres (written by write_fakenect_dump)", where);
    return;
  }
  // fakenect hands the file's bytes over unchanged: look at them as stored.
  const SampleOrder o = kinect_sample_order(reinterpret_cast<const std::uint8_t*>(depth.data()), depth.size(),
                                            where + ", first depth frame");
  swap_bytes_ = (o == SampleOrder::big_endian) != (std::endian::native == std::endian::big);
  spdlog::info("{}: raw 11-bit disparity, 16-bit samples stored {}", where, sample_order_name(o));
  make_registrar();
}

bool KinectSource::next(RgbdFrame& frame) {
  if (params_.max_frames > 0 && delivered_ >= params_.max_frames) return false;
  Raw raw;
  for (;;) {
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
    if (discarded_ >= params_.first_frame) break;
    ++discarded_;  // input.first_frame: frames before it are read and dropped
  }
  if (replay_ && delivered_ == 0) decide_replay_content(raw.depth);
  frame.index = delivered_++;
  frame.timestamp = raw.timestamp;
  frame.intrinsics = K_;
  reserve_frame_images(frame, kW, kH, pinned_);
  if (raw_depth_) {
    if (swap_bytes_)
      for (std::uint16_t& v : raw.depth) v = static_cast<std::uint16_t>(v >> 8 | v << 8);
    registrar_->register_depth(raw.depth.data(), frame.depth);
  } else {
    float* d = frame.depth.buffer().data();
    // FREENECT_DEPTH_NO_VALUE is 0: no reading stays 0.
    for (int i = 0; i < kW * kH; ++i) d[i] = raw.depth[i] * 1e-3f;
  }
  std::memcpy(frame.rgb.buffer().data(), raw.rgb.data(), raw.rgb.size());
  frame.accelerometer.reset();
  if (raw.has_accel) frame.accelerometer = raw.accel;
  frame.ground_truth.reset();
  return true;
}

}  // namespace seamless
