// The factories of the external trackers this build has (an empty function when the library is
// missing): the one place that knows which implementation files were compiled.
#include "recon/external/odometry.hpp"
#include "seamless/build_config.hpp"

namespace seamless::external {

#if SEAMLESS_HAS_OPENCV
std::unique_ptr<Odometry> make_opencv_odometry(OpenCvMethod m, const Intrinsics& K);  // opencv_odometry.cpp
#endif
#if SEAMLESS_HAS_PCL
std::unique_ptr<Odometry> make_pcl_gicp_odometry(const Intrinsics& K);  // pcl_gicp_odometry.cpp
#endif

OdometryFactory opencv_factory(OpenCvMethod m) {
#if SEAMLESS_HAS_OPENCV
  return [m](const Intrinsics& K, const TrackerParams&) { return make_opencv_odometry(m, K); };
#else
  (void)m;
  return {};
#endif
}

OdometryFactory pcl_gicp_factory() {
#if SEAMLESS_HAS_PCL
  return [](const Intrinsics& K, const TrackerParams&) { return make_pcl_gicp_odometry(K); };
#else
  return {};
#endif
}

}  // namespace seamless::external
