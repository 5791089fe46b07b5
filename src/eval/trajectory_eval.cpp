#include "eval/trajectory_eval.hpp"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "core/error.hpp"

namespace seamless {

namespace {

Eigen::Isometry3d to_iso(const TumPose& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.q[3], p.q[0], p.q[1], p.q[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.t[0], p.t[1], p.t[2]);
  return T;
}

TumPose from_iso(double timestamp, const Eigen::Isometry3d& T) {
  Eigen::Quaterniond q(T.linear());
  TumPose p;
  p.timestamp = timestamp;
  for (int i = 0; i < 3; ++i) p.t[i] = T.translation()[i];
  p.q[0] = q.x(); p.q[1] = q.y(); p.q[2] = q.z(); p.q[3] = q.w();
  return p;
}

double rotation_angle_deg(const Eigen::Matrix3d& R) {
  double c = std::clamp((R.trace() - 1.0) / 2.0, -1.0, 1.0);
  return std::acos(c) * 180.0 / M_PI;
}

}  // namespace

ErrorStats error_stats(std::vector<double> e) {
  ErrorStats s;
  s.count = e.size();
  if (e.empty()) return s;
  double sum = 0, sq = 0;
  for (double v : e) {
    sum += v;
    sq += v * v;
  }
  s.mean = sum / e.size();
  s.rmse = std::sqrt(sq / e.size());
  s.std = std::sqrt(std::max(0.0, sq / e.size() - s.mean * s.mean));
  std::sort(e.begin(), e.end());
  s.min = e.front();
  s.max = e.back();
  s.median = e.size() % 2 ? e[e.size() / 2] : 0.5 * (e[e.size() / 2 - 1] + e[e.size() / 2]);
  return s;
}

std::vector<std::pair<std::size_t, std::size_t>> associate(const Trajectory& est, const Trajectory& gt, double max_dt) {
  struct Cand {
    double dt;
    std::size_t i, j;
  };
  std::vector<Cand> cands;
  for (std::size_t i = 0; i < est.size(); ++i) {
    auto lo = std::lower_bound(gt.begin(), gt.end(), est[i].timestamp - max_dt,
                               [](const TumPose& p, double t) { return p.timestamp < t; });
    for (auto it = lo; it != gt.end() && it->timestamp <= est[i].timestamp + max_dt; ++it)
      cands.push_back({std::fabs(it->timestamp - est[i].timestamp), i, static_cast<std::size_t>(it - gt.begin())});
  }
  std::sort(cands.begin(), cands.end(), [](const Cand& a, const Cand& b) { return a.dt < b.dt; });
  std::vector<char> used_e(est.size(), 0), used_g(gt.size(), 0);
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const Cand& c : cands)
    if (!used_e[c.i] && !used_g[c.j]) {
      used_e[c.i] = used_g[c.j] = 1;
      pairs.emplace_back(c.i, c.j);
    }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

AteResult compute_ate(const Trajectory& est, const Trajectory& gt, double max_dt) {
  auto pairs = associate(est, gt, max_dt);
  if (pairs.size() < 3)
    throw Error("ATE needs at least 3 poses whose timestamps match within " + std::to_string(max_dt) + " s; found " +
                std::to_string(pairs.size()) + " (are both files TUM trajectories of the same sequence?)");
  Eigen::Matrix3Xd src(3, pairs.size()), dst(3, pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const TumPose &e = est[pairs[k].first], &g = gt[pairs[k].second];
    src.col(k) = Eigen::Vector3d(e.t[0], e.t[1], e.t[2]);
    dst.col(k) = Eigen::Vector3d(g.t[0], g.t[1], g.t[2]);
  }
  // Least-squares rigid alignment of the positions (Umeyama 1991 without scale; same as Horn).
  Eigen::Matrix4d A = Eigen::umeyama(src, dst, false);
  Eigen::Isometry3d gt_T_est(A);
  AteResult r;
  for (int i = 0; i < 3; ++i) {
    r.t[i] = A(i, 3);
    for (int j = 0; j < 3; ++j) r.R[i][j] = A(i, j);
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    Eigen::Vector3d moved = gt_T_est * src.col(k);
    r.errors.push_back((moved - dst.col(k)).norm());
    r.times.push_back(est[pairs[k].first].timestamp);
    r.aligned.push_back(from_iso(est[pairs[k].first].timestamp, gt_T_est * to_iso(est[pairs[k].first])));
  }
  r.trans = error_stats(r.errors);
  return r;
}

RpeResult compute_rpe(const Trajectory& est, const Trajectory& gt, double delta, const std::string& unit,
                      double max_dt) {
  if (unit != "frames" && unit != "seconds") throw Error("RPE delta unit must be 'frames' or 'seconds', not '" + unit + "'");
  if (!(delta > 0)) throw Error("RPE delta must be positive");
  auto pairs = associate(est, gt, max_dt);
  RpeResult r;
  for (std::size_t a = 0; a < pairs.size(); ++a) {
    std::size_t b = a;
    if (unit == "frames") {
      b = a + static_cast<std::size_t>(std::llround(delta));
    } else {
      double t0 = est[pairs[a].first].timestamp;
      while (b < pairs.size() && est[pairs[b].first].timestamp - t0 < delta) ++b;
    }
    if (b >= pairs.size()) break;
    // E = (Q_a^-1 Q_b)^-1 (P_a^-1 P_b): TUM's relative pose error (Sturm et al. 2012, eq. 1).
    Eigen::Isometry3d Pa = to_iso(est[pairs[a].first]), Pb = to_iso(est[pairs[b].first]);
    Eigen::Isometry3d Qa = to_iso(gt[pairs[a].second]), Qb = to_iso(gt[pairs[b].second]);
    Eigen::Isometry3d E = (Qa.inverse() * Qb).inverse() * (Pa.inverse() * Pb);
    r.trans_errors.push_back(E.translation().norm());
    r.rot_errors.push_back(rotation_angle_deg(E.linear()));
    r.times.push_back(est[pairs[a].first].timestamp);
  }
  if (r.trans_errors.empty())
    throw Error("RPE: no pose pairs " + std::to_string(delta) + " " + unit + " apart among " +
                std::to_string(pairs.size()) + " associated poses");
  r.trans = error_stats(r.trans_errors);
  r.rot = error_stats(r.rot_errors);
  return r;
}

}  // namespace seamless
