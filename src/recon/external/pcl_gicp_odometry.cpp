// PCL's generalized ICP (Segal, Haehnel, Thrun, "Generalized-ICP", RSS 2009: plane-to-plane
// through per-point covariances of the 20 nearest neighbours) frame to frame, as an external
// tracker. Compiled only when SEAMLESS_HAS_PCL.
//
// Settings (docs/TRACKING.md): every pixel with depth in (0, 4 m] (the range OpenCV's odometries
// use by default) back-projected with the source's intrinsics, then a 2 cm voxel grid (about 10^4
// points from the 3 * 10^5 of a 640x480 view, which keeps GICP's k-d tree searches at a few hundred
// milliseconds a frame on one CPU core); correspondences up to 0.25 m apart (a point 3 m away moves
// about 0.25 m when the camera turns 5 degrees, the fast end of freiburg1_rpy), at most 50
// iterations, PCL's defaults otherwise.
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>

#include <cmath>

#include "recon/external/frame_cache.hpp"
#include "recon/external/odometry.hpp"

namespace seamless::external {

namespace {

using Cloud = pcl::PointCloud<pcl::PointXYZ>;

constexpr float kMaxDepth = 4.f;             // metres
constexpr float kVoxel = 0.02f;              // metres
constexpr double kMaxCorrespondence = 0.25;  // metres
constexpr int kMaxIterations = 50;

Cloud::Ptr to_cloud(const RgbdFrame& f, const Intrinsics& K) {
  const int w = f.depth.width(), h = f.depth.height();
  std::vector<float> d = f.depth.to_host();
  Cloud::Ptr full(new Cloud);
  full->reserve(d.size());
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      float z = d[static_cast<std::size_t>(v) * w + u];
      if (!(z > 0.f && z <= kMaxDepth)) continue;
      vec3 p = K.unproject(static_cast<float>(u), static_cast<float>(v), z);
      full->push_back(pcl::PointXYZ(p.x, p.y, p.z));
    }
  Cloud::Ptr out(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(full);
  grid.setLeafSize(kVoxel, kVoxel, kVoxel);
  grid.filter(*out);
  return out;
}

Eigen::Matrix4f to_eigen(const SE3& T) {
  Eigen::Matrix4f m = Eigen::Matrix4f::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m(r, c) = T.R.m[r][c];
    m(r, 3) = (&T.t.x)[r];
  }
  return m;
}

SE3 from_eigen(const Eigen::Matrix4f& m) {
  double a[4][4];
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) a[r][c] = m(r, c);
  return rigid_from_matrix(a);
}

class PclGicpOdometry : public Odometry {
 public:
  explicit PclGicpOdometry(const Intrinsics& K) : K_(K) {
    gicp_.setMaxCorrespondenceDistance(kMaxCorrespondence);
    gicp_.setMaximumIterations(kMaxIterations);
  }

  std::optional<OdometryEstimate> prev_T_cur(const RgbdFrame& prev, const RgbdFrame& cur,
                                             const std::optional<SE3>& guess) override {
    auto prepare = [this](const RgbdFrame& f) { return to_cloud(f, K_); };  // once per frame
    Cloud::Ptr target = cache_.get(prev, prepare), source = cache_.get(cur, prepare);
    if (source->size() < 20 || target->size() < 20) return std::nullopt;  // k = 20 neighbours per covariance
    // Source = current, target = previous: the final transformation maps current points onto the
    // previous frame's, i.e. it is prev_T_cur.
    gicp_.setInputSource(source);
    gicp_.setInputTarget(target);
    Cloud aligned;
    gicp_.align(aligned, guess ? to_eigen(*guess) : Eigen::Matrix4f::Identity());
    if (!gicp_.hasConverged()) return std::nullopt;
    OdometryEstimate e;
    e.prev_T_cur = from_eigen(gicp_.getFinalTransformation());
    // Mean squared distance of the aligned points to their nearest neighbours within the
    // correspondence distance (PCL's fitness score).
    e.residual_rms = std::sqrt(gicp_.getFitnessScore(kMaxCorrespondence));
    return e;
  }
  std::string name() const override { return "PCL GICP"; }

 private:
  Intrinsics K_;
  pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp_;
  TwoFrameCache<Cloud::Ptr> cache_;
};

}  // namespace

std::unique_ptr<Odometry> make_pcl_gicp_odometry(const Intrinsics& K) { return std::make_unique<PclGicpOdometry>(K); }

}  // namespace seamless::external
