#include "io/callback_source.hpp"

#include <algorithm>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/io/undistort.hpp"

namespace seamless {

namespace {
bool distorted(const Intrinsics& K) {
  return std::any_of(std::begin(K.dist), std::end(K.dist), [](float d) { return d != 0.f; });
}
}  // namespace

CallbackSource::CallbackSource(Fetch fetch, const Intrinsics& K, bool undistort, std::optional<std::int64_t> size,
                               std::int64_t max_frames, std::string name)
    : fetch_(std::move(fetch)), K_(K), undistort_(undistort && distorted(K)), size_(size), max_frames_(max_frames),
      name_(std::move(name)) {
  if (max_frames_ > 0) size_ = size_ ? std::min(*size_, max_frames_) : max_frames_;
}

Intrinsics CallbackSource::intrinsics() const {
  Intrinsics K = K_;
  if (undistort_) std::fill(std::begin(K.dist), std::end(K.dist), 0.f);
  return K;
}

bool CallbackSource::next(RgbdFrame& frame) {
  if (max_frames_ > 0 && delivered_ >= max_frames_) return false;
  RgbdFrame& f = undistort_ ? raw_ : frame;
  f.accelerometer.reset(), f.ground_truth.reset();
  if (!fetch_(f)) return false;
  const std::string which = name_ + " frame " + std::to_string(delivered_);
  if (f.depth.width() != K_.width || f.depth.height() != K_.height)
    throw InputError(which + ": the depth image is " + std::to_string(f.depth.width()) + "x" +
                     std::to_string(f.depth.height()) + " but the intrinsics say " + std::to_string(K_.width) + "x" +
                     std::to_string(K_.height));
  if (f.rgb.width() != f.depth.width() || f.rgb.height() != f.depth.height())
    throw InputError(which + ": the colour image is " + std::to_string(f.rgb.width()) + "x" +
                     std::to_string(f.rgb.height()) + ", the depth image " + std::to_string(f.depth.width()) + "x" +
                     std::to_string(f.depth.height()));
  if (undistort_) {  // on the host, as the TUM source: this is input decoding
    reserve_frame_images(frame, K_.width, K_.height, false);
    with_exec(Device::CPU, [&]<class E>(const E& ex) {
      if (undistort_map_.width() != K_.width) {
        undistort_map_ = Image<vec2>(K_.width, K_.height, Device::CPU);
        kernels::Undistort<E>::undistort_map(ex, K_, undistort_map_.view());
      }
      kernels::Undistort<E>::remap_depth(ex, undistort_map_.cview(), raw_.depth.cview(), frame.depth.view());
      kernels::Undistort<E>::remap_rgb(ex, undistort_map_.cview(), raw_.rgb.cview(), frame.rgb.view());
    });
    frame.timestamp = raw_.timestamp;
    frame.accelerometer = raw_.accelerometer, frame.ground_truth = raw_.ground_truth;
  }
  frame.intrinsics = intrinsics();
  frame.index = delivered_++;
  return true;
}

}  // namespace seamless
