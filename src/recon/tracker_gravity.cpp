#include "recon/tracker_gravity.hpp"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <vector>

#include "core/error.hpp"

namespace seamless {

namespace {
constexpr float kPlaneTol = 0.02f;     // metres: inlier distance (a few Kinect noise sigmas at 2 m)
constexpr float kNormalCos = 0.9397f;  // cos 20 deg: inlier normal agreement
constexpr float kUprightCos = 0.5f;    // cos 60 deg: candidate normals near the camera's up
constexpr int kCandidates = 400;

struct Plane {
  vec3 n;   // unit, pointing up (towards the camera side)
  float d;  // n . x + d = 0
};

int count_inliers(const std::vector<vec3>& v, const std::vector<vec3>& n, const Plane& p) {
  int c = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::fabs(dot(p.n, v[i]) + p.d) < kPlaneTol && dot(p.n, n[i]) > kNormalCos) ++c;
  return c;
}

// Least-squares plane through the inliers (smallest eigenvector of their covariance).
vec3 refit_normal(const std::vector<vec3>& v, const std::vector<vec3>& n, const Plane& p) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> pts;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (std::fabs(dot(p.n, v[i]) + p.d) < kPlaneTol && dot(p.n, n[i]) > kNormalCos) {
      pts.emplace_back(v[i].x, v[i].y, v[i].z);
      mean += pts.back();
    }
  if (pts.size() < 3) return p.n;
  mean /= static_cast<double>(pts.size());
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& q : pts) C += (q - mean) * (q - mean).transpose();
  Eigen::Vector3d e = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(0);
  vec3 r{static_cast<float>(e.x()), static_cast<float>(e.y()), static_cast<float>(e.z())};
  return dot(r, p.n) < 0 ? -r : r;
}
}  // namespace

GravityEstimate floor_plane_gravity(const FramePyramid& frame) {
  // The coarsest level: a few thousand points are plenty for one plane, and this runs once.
  const PyramidLevel& lv = frame.level(frame.levels() - 1);
  std::vector<vec3> vall = lv.vertices.to_host(), nall = lv.normals.to_host(), v, n;
  for (std::size_t i = 0; i < vall.size(); ++i)
    if (vall[i].z > 0 && length2(nall[i]) > 0) {
      v.push_back(vall[i]);
      n.push_back(nall[i]);
    }
  GravityEstimate g;
  g.source = "floor";
  if (v.size() < 50) return g;
  const vec3 up_cam{0.f, -1.f, 0.f};
  Plane best{};
  int best_count = 0;
  const std::size_t stride = std::max<std::size_t>(1, v.size() / kCandidates);
  for (std::size_t i = 0; i < v.size(); i += stride) {
    // Normals face the camera, so a plane below the camera has a normal with an up component.
    if (dot(n[i], up_cam) < kUprightCos) continue;
    Plane p{n[i], -dot(n[i], v[i])};
    if (p.d <= 0) continue;  // the camera must be on the side the normal points to
    int c = count_inliers(v, n, p);
    if (c > best_count) best_count = c, best = p;
  }
  // A plane covering under 5% of the view is as likely a shelf or a box as the floor.
  g.support = static_cast<double>(best_count) / v.size();
  if (g.support < 0.05) return g;
  g.down = -refit_normal(v, n, best);
  g.found = true;
  return g;
}

GravityEstimate estimate_gravity(const TrackerParams& p, const std::optional<vec3>& accelerometer,
                                 const FramePyramid& frame) {
  GravityEstimate g;
  const GravitySource how = p.gravity;
  if (how == GravitySource::none) return g;
  if (how == GravitySource::fixed) {
    // A loaded config was checked already (TrackerParams::validate); this is for params built in code.
    if (length2(p.fixed_gravity) == 0) throw ConfigError("tracker.fixed_gravity is the zero vector; give a direction");
    return {normalize(p.fixed_gravity), "fixed", true, 0};
  }
  if ((how == GravitySource::accelerometer || how == GravitySource::automatic) && accelerometer &&
      length2(*accelerometer) > 0) {
    // At rest the accelerometer measures the reaction to gravity: it points up.
    return {normalize(-*accelerometer), "accelerometer", true, 0};
  }
  if (how == GravitySource::accelerometer) {
    g.source = "accelerometer";
    return g;  // asked for, but this frame has none: reported as not found
  }
  return floor_plane_gravity(frame);
}

SE3 gravity_aligned_pose(vec3 down) {
  vec3 up = normalize(-down);
  if (length2(up) == 0) return SE3::identity();
  // World axes expressed in camera coordinates: y = up, z = viewing direction made horizontal.
  vec3 fwd{0.f, 0.f, 1.f};
  vec3 z = fwd - up * dot(fwd, up);
  if (length2(z) < 1e-8f) z = vec3{0.f, 1.f, 0.f} - up * up.y;  // looking straight down or up
  z = normalize(z);
  vec3 x = cross(up, z);
  // camera_R_world has the world axes as columns; world_R_camera is its transpose (rows).
  SE3 T = SE3::identity();
  T.R = {{{x.x, x.y, x.z}, {up.x, up.y, up.z}, {z.x, z.y, z.z}}};
  return T;
}

}  // namespace seamless
