// The factories of the external trackers this build has (an empty function when the library is
// missing): the one place that knows which implementation files were compiled. And the conversion
// of a library's 4x4 result into an exactly rigid SE3.
#include "recon/external/odometry.hpp"

#include <Eigen/Dense>

#include "seamless/build_config.hpp"

namespace seamless::external {

SE3 rigid_from_matrix(const double m[4][4]) {
  Eigen::Matrix3d A;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) A(r, c) = m[r][c];
  // Nearest rotation (Frobenius) by SVD, with the sign fixed so det = +1.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0 ? -1.0 : 1.0;
  Eigen::Matrix3d R = svd.matrixU() * D * svd.matrixV().transpose();
  SE3 T = SE3::identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.R.m[r][c] = static_cast<float>(R(r, c));
    (&T.t.x)[r] = static_cast<float>(m[r][3]);
  }
  return T;
}

SE3 make_rigid(const SE3& T) {
  double m[4][4] = {};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[r][c] = T.R.m[r][c];
    m[r][3] = (&T.t.x)[r];
  }
  return rigid_from_matrix(m);
}

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
