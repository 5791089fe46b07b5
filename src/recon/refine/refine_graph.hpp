// The pose graph over keyframe poses and its Ceres solve (internal to src/recon/refine).
//
// Nodes: world_T_k per keyframe (unit quaternion + translation). Edge (i, j) with measurement
// Z = i_T_j and information Lambda (6x6, order omega then upsilon as in kernels/recon/icp.hpp):
//   D = (T_i^-1 T_j) Z^-1 = exp(e),  e = (omega, upsilon) in keyframe i's frame,
//   E_ij = e^T Lambda e                       (Kerl et al. 2013, eq. 18; Choi et al. 2015, eq. 3)
// The left perturbation in the reference camera's frame is the tracker's own update
// (ref_T_cur <- exp(xi) ref_T_cur), so the 6x6 J^T J of the pairwise alignment is Lambda's shape
// directly. omega = 2 vec(q_D) (first order; the corrections are small). The first keyframe is
// held fixed (gauge). Loop edges (non-consecutive pairs) go through a robust loss.
#pragma once
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <string>
#include <vector>

#include "recon/refine/refine_params.hpp"

namespace seamless::refine_detail {

struct Pose {
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
};
Pose compose(const Pose& a, const Pose& b);
Pose inverse(const Pose& a);
// a + alpha (b - a): slerp of the rotation, lerp of the translation.
Pose blend(const Pose& a, const Pose& b, double alpha);

struct Edge {
  int i = 0, j = 0;                  // keyframe indices (positions in the node vector)
  Pose z;                            // measured i_T_j
  Eigen::Matrix<double, 6, 6> info;  // Lambda, symmetric positive definite
  bool robust = false;               // loop edge: robust loss
  bool odometry = false;
};

struct GraphSolution {
  std::vector<Pose> poses;
  int iterations = 0;
  double initial_cost = 0, final_cost = 0;
  bool converged = false;
  std::string message;
};

// Solves the graph from `initial` (keyframe 0 fixed). Needs Ceres (refine_available()).
GraphSolution solve_pose_graph(const std::vector<Pose>& initial, const std::vector<Edge>& edges,
                               const RefineParams& params);

}  // namespace seamless::refine_detail
