// External frame-to-frame odometry (the tracker comparison): trackers of other libraries
// (OpenCV contrib's rgbd module, PCL's generalized ICP) behind one small interface, so that
// TrackingSession can chain their relative poses exactly as it chains ours and `seamless eval`
// compares like with like. Host images only: these libraries run on the CPU.
//
// Adding a tracker: implement Odometry in a file of this folder (compiled only when its library is
// found, see external.cmake) and add one entry to tracker_registry() in tracker_sequence.cpp.
#pragma once
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "io/frame_source.hpp"
#include "recon/tracker_params.hpp"

namespace seamless::external {

// What one library call gives back. Quantities a library does not report stay NaN (doubles) or 0
// (counts); docs/TRACKING.md lists what each tracker fills.
struct OdometryEstimate {
  SE3 prev_T_cur = SE3::identity();  // maps points of the current camera into the previous camera
  double residual_rms = std::numeric_limits<double>::quiet_NaN();  // metres, where the library says
  double inlier_ratio = std::numeric_limits<double>::quiet_NaN();
  std::int64_t inliers = 0;
  int iterations = 0;
};

class Odometry {
 public:
  virtual ~Odometry() = default;
  // The motion from `prev` to `cur` (both host frames with depth in metres, 0 = no reading, and
  // rgb), starting from `guess` (prev_T_cur) when given. std::nullopt when the library reports
  // failure (too few correspondences, no solution, its own motion limits): the frame is lost.
  virtual std::optional<OdometryEstimate> prev_T_cur(const RgbdFrame& prev, const RgbdFrame& cur,
                                                     const std::optional<SE3>& guess) = 0;
  virtual std::string name() const = 0;
};

// Builds an external tracker for a camera with intrinsics K (the source's, undistorted) and the
// tracker section of the experiment (the settings the libraries share with ours, e.g. dist_threshold).
using OdometryFactory = std::function<std::unique_ptr<Odometry>(const Intrinsics& K, const TrackerParams& p)>;

// A library's 4x4 result (row-major, rows 0-2 used) as an exactly rigid transform: the nearest
// rotation by SVD. A chain of poses must stay rigid: a slightly non-orthonormal pose, fed back as
// the next initial guess, grows frame after frame (seen with OpenCV's initRt on freiburg1_rpy).
SE3 rigid_from_matrix(const double m[4][4]);
SE3 make_rigid(const SE3& T);

// The factories this build has: an empty function when the library is missing.
enum class OpenCvMethod { rgbd, icp, rgbd_icp, fast_icp };
OdometryFactory opencv_factory(OpenCvMethod m);
OdometryFactory pcl_gicp_factory();

}  // namespace seamless::external
