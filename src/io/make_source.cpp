#include "core/error.hpp"
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
  if (params.source == "tum") return std::make_unique<TumSource>(params);
  if (params.source == "synthetic") return std::make_unique<SyntheticSource>(params, device);
  if (params.source == "kinect") {
#if SEAMLESS_HAS_FREENECT
    return std::make_unique<KinectSource>(params);
#else
    throw Error("input.source is kinect but this build has no libfreenect: apt-get install libfreenect-dev, reconfigure");
#endif
  }
  throw Error("unknown input.source '" + params.source + "': use synthetic, tum or kinect");
}

}  // namespace seamless
