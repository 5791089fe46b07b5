#include "recon/refine/refine_graph.hpp"

#include <Eigen/Cholesky>

#include "core/error.hpp"
#include "seamless/build_config.hpp"

#if SEAMLESS_HAS_CERES
#include <ceres/ceres.h>
#endif

namespace seamless::refine_detail {

Pose compose(const Pose& a, const Pose& b) { return {(a.q * b.q).normalized(), a.t + a.q * b.t}; }

Pose inverse(const Pose& a) {
  Eigen::Quaterniond qi = a.q.conjugate();
  return {qi, -(qi * a.t)};
}

Pose blend(const Pose& a, const Pose& b, double alpha) {
  return {a.q.slerp(alpha, b.q).normalized(), (1.0 - alpha) * a.t + alpha * b.t};
}

#if SEAMLESS_HAS_CERES
namespace {

// Residual of one edge, r = L^T e with Lambda = L L^T (refine_graph.hpp for e). Autodiff: the
// Jacobians of the quaternion algebra are exact, so Levenberg-Marquardt converges in a few steps.
struct EdgeCost {
  Eigen::Quaterniond qz_inv;
  Eigen::Vector3d tz;
  Eigen::Matrix<double, 6, 6> sqrt_info;

  template <class T> bool operator()(const T* qi_, const T* ti_, const T* qj_, const T* tj_, T* res) const {
    Eigen::Map<const Eigen::Quaternion<T>> qi(qi_), qj(qj_);
    Eigen::Map<const Eigen::Matrix<T, 3, 1>> ti(ti_), tj(tj_);
    const Eigen::Quaternion<T> qi_inv = qi.conjugate();
    const Eigen::Quaternion<T> qe = qi_inv * qj;  // E = T_i^-1 T_j
    const Eigen::Matrix<T, 3, 1> te = qi_inv * (tj - ti);
    const Eigen::Quaternion<T> qd = qe * qz_inv.cast<T>();  // D = E Z^-1
    const Eigen::Matrix<T, 3, 1> td = te - qd * tz.cast<T>();
    const T s = qd.w() < T(0) ? T(-2) : T(2);  // q and -q are the same rotation
    Eigen::Matrix<T, 6, 1> e;
    e << s * qd.x(), s * qd.y(), s * qd.z(), td.x(), td.y(), td.z();
    Eigen::Map<Eigen::Matrix<T, 6, 1>> r(res);
    r = sqrt_info.cast<T>() * e;
    return true;
  }
};

ceres::LossFunction* make_loss(const RefineParams& p) {
  if (p.robust_loss == RobustLoss::huber) return new ceres::HuberLoss(p.robust_scale);
  if (p.robust_loss == RobustLoss::cauchy) return new ceres::CauchyLoss(p.robust_scale);
  return nullptr;
}

ceres::CostFunction* make_cost(const Edge& e) {
  Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(e.info);
  if (llt.info() != Eigen::Success)
    throw Error("refine: edge " + std::to_string(e.i) + "-" + std::to_string(e.j) +
                " has an information matrix that is not positive definite (a degenerate alignment got through)");
  auto* c = new EdgeCost{e.z.q.conjugate(), e.z.t, llt.matrixU()};
  return new ceres::AutoDiffCostFunction<EdgeCost, 6, 4, 3, 4, 3>(c);
}

}  // namespace

GraphSolution solve_pose_graph(const std::vector<Pose>& initial, const std::vector<Edge>& edges,
                               const RefineParams& params) {
  GraphSolution out;
  out.poses = initial;
  ceres::Problem problem;
  for (Pose& p : out.poses) {
    problem.AddParameterBlock(p.q.coeffs().data(), 4, new ceres::EigenQuaternionManifold);
    problem.AddParameterBlock(p.t.data(), 3);
  }
  for (const Edge& e : edges) {
    Pose& a = out.poses.at(e.i);
    Pose& b = out.poses.at(e.j);
    problem.AddResidualBlock(make_cost(e), e.robust ? make_loss(params) : nullptr, a.q.coeffs().data(), a.t.data(),
                             b.q.coeffs().data(), b.t.data());
  }
  // Gauge freedom: the first keyframe defines the world (as the tracker's first frame does).
  problem.SetParameterBlockConstant(out.poses[0].q.coeffs().data());
  problem.SetParameterBlockConstant(out.poses[0].t.data());

  ceres::Solver::Options opt;
  opt.minimizer_type = ceres::TRUST_REGION;
  opt.trust_region_strategy_type = ceres::LEVENBERG_MARQUARDT;
  opt.linear_solver_type = out.poses.size() <= 150 ? ceres::DENSE_NORMAL_CHOLESKY : ceres::SPARSE_NORMAL_CHOLESKY;
  opt.max_num_iterations = params.max_iterations;
  opt.num_threads = 1;
  opt.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(opt, &problem, &summary);
  if (!summary.IsSolutionUsable()) throw Error("refine: Ceres found no usable solution: " + summary.message);
  out.iterations = static_cast<int>(summary.iterations.size()) - 1;  // the first entry is the initial state
  out.initial_cost = summary.initial_cost;
  out.final_cost = summary.final_cost;
  out.converged = summary.termination_type == ceres::CONVERGENCE;
  out.message = summary.BriefReport();
  for (Pose& p : out.poses) p.q.normalize();
  return out;
}

#else

GraphSolution solve_pose_graph(const std::vector<Pose>&, const std::vector<Edge>&, const RefineParams&) {
  throw Error("refine: this build has no Ceres; install libceres-dev and reconfigure to use refine.enabled");
}

#endif

}  // namespace seamless::refine_detail
