#include <spdlog/spdlog.h>
#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/error.hpp"

#include "io/fakenect_source.hpp"
#include "io/frame_folder_source.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "io/synthetic_source.hpp"
#include "io/tum_source.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_FREENECT
#include "io/kinect_source.hpp"
#endif

namespace seamless {

std::unique_ptr<FrameSource> make_source(const InputParams& params, Device device) {
  const bool pinned = device == Device::CUDA;
  if (params.source == InputSource::fakenect) return std::make_unique<FakenectSource>(params, pinned);
  // A fakenect-record folder is told by its INDEX.txt whatever source names it.
  if (params.source != InputSource::synthetic && is_fakenect_folder(params.path)) {
    spdlog::info("input.path '{}' holds INDEX.txt: read as a fakenect-record folder (input.source: fakenect)",
                 params.path);
    return std::make_unique<FakenectSource>(params, pinned);
  }
  if (params.source == InputSource::tum) return std::make_unique<TumSource>(params, pinned);
  if (params.source == InputSource::frames) return std::make_unique<FrameFolderSource>(params, pinned);
  if (params.source == InputSource::synthetic) return std::make_unique<SyntheticSource>(params, device);
  if (params.source == InputSource::kinect) {
#if SEAMLESS_HAS_FREENECT
    return std::make_unique<KinectSource>(params, pinned);
#else
    throw ConfigError(
        "input.source is kinect but this build has no libfreenect: apt-get install libfreenect-dev, reconfigure");
#endif
  }
  throw ConfigError("unknown input.source '" + std::string(enum_name(params.source)) +
                    "': use synthetic, tum, frames, kinect or fakenect");
}

namespace {
template <class T> void reserve_host_image(Image<T>& im, int w, int h, bool pinned) {
  // Without a usable GPU, pinned_host falls back to ordinary memory: that fits as well.
  bool fits = im.width() == w && im.height() == h && im.device() == Device::CPU &&
              (!pinned || memory::is_pinned(im.buffer().data()) || !cuda_available());
  if (!fits) im = pinned ? Image<T>::pinned_host(w, h) : Image<T>(w, h, Device::CPU);
}
}  // namespace

void reserve_frame_images(RgbdFrame& frame, int w, int h, bool pinned) {
  reserve_host_image(frame.depth, w, h, pinned);
  reserve_host_image(frame.rgb, w, h, pinned);
}

}  // namespace seamless
