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
  p.q[0] = q.x();
  p.q[1] = q.y();
  p.q[2] = q.z();
  p.q[3] = q.w();
  return p;
}

// The rotation angle of R, from both its sine and cosine (2 sin = |vee(R - R^T)|, 2 cos = tr R - 1):
// acos of the trace alone loses half the digits near zero, where per-frame errors live.
double rotation_angle_deg(const Eigen::Matrix3d& R) {
  const Eigen::Vector3d v(R(2, 1) - R(1, 2), R(0, 2) - R(2, 0), R(1, 0) - R(0, 1));
  return std::atan2(v.norm(), R.trace() - 1.0) * 180.0 / M_PI;
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

Alignment parse_alignment(const std::string& name) {
  if (name == "se3") return Alignment::se3;
  if (name == "sim3") return Alignment::sim3;
  if (name == "none") return Alignment::none;
  throw Error("unknown alignment '" + name + "': use se3 (rigid), sim3 (rigid + scale) or none");
}

const char* to_string(Alignment a) { return a == Alignment::se3 ? "se3" : a == Alignment::sim3 ? "sim3" : "none"; }

std::vector<std::pair<std::size_t, std::size_t>> associate(const Trajectory& est, const Trajectory& gt, double max_dt,
                                                           double offset) {
  struct Cand {
    double dt;
    std::size_t i, j;
  };
  std::vector<Cand> cands;
  for (std::size_t i = 0; i < est.size(); ++i) {
    const double te = est[i].timestamp + offset;
    auto lo =
        std::lower_bound(gt.begin(), gt.end(), te - max_dt, [](const TumPose& p, double t) { return p.timestamp < t; });
    for (auto it = lo; it != gt.end() && it->timestamp <= te + max_dt; ++it)
      cands.push_back({std::fabs(it->timestamp - te), i, static_cast<std::size_t>(it - gt.begin())});
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

namespace {

using Pairs = std::vector<std::pair<std::size_t, std::size_t>>;

// Positions of the associated poses, estimate (src) and ground truth (dst), one column each.
void positions(const Trajectory& est, const Trajectory& gt, const Pairs& pairs, Eigen::Matrix3Xd& src,
               Eigen::Matrix3Xd& dst) {
  src.resize(3, pairs.size());
  dst.resize(3, pairs.size());
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const TumPose &e = est[pairs[k].first], &g = gt[pairs[k].second];
    src.col(k) = Eigen::Vector3d(e.t[0], e.t[1], e.t[2]);
    dst.col(k) = Eigen::Vector3d(g.t[0], g.t[1], g.t[2]);
  }
}

// The least-squares similarity dst ~ s R src + t (Umeyama 1991, eq. 40-42; with_scale false
// gives the rigid motion, the same as Horn 1987), as a 4x4 matrix [sR t; 0 1].
Eigen::Matrix4d alignment(const Eigen::Matrix3Xd& src, const Eigen::Matrix3Xd& dst, Alignment a) {
  if (a == Alignment::none) return Eigen::Matrix4d::Identity();
  return Eigen::umeyama(src, dst, a == Alignment::sim3);
}

Pairs associated(const Trajectory& est, const Trajectory& gt, const EvalOptions& o, const char* what) {
  Pairs pairs = associate(est, gt, o.t_max_diff, o.offset);
  if (pairs.size() < 3)
    throw Error(std::string(what) + " needs at least 3 poses whose timestamps match within " +
                std::to_string(o.t_max_diff) + " s (offset " + std::to_string(o.offset) + " s); found " +
                std::to_string(pairs.size()) + " (are both files TUM trajectories of the same sequence?)");
  return pairs;
}

}  // namespace

AteResult compute_ate(const Trajectory& est, const Trajectory& gt, const EvalOptions& o) {
  const Pairs pairs = associated(est, gt, o, "ATE");
  Eigen::Matrix3Xd src, dst;
  positions(est, gt, pairs, src, dst);
  const Eigen::Matrix4d A = alignment(src, dst, o.align);
  AteResult r;
  r.align = o.align;
  // A's upper-left block is s R with R a rotation: s is the length of any of its columns.
  if (o.align == Alignment::sim3) r.scale = A.block<3, 1>(0, 0).norm();
  const Eigen::Matrix3d R = A.block<3, 3>(0, 0) / r.scale;
  for (int i = 0; i < 3; ++i) {
    r.t[i] = A(i, 3);
    for (int j = 0; j < 3; ++j) r.R[i][j] = R(i, j);
  }
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    const Eigen::Vector3d moved = A.block<3, 3>(0, 0) * src.col(k) + A.block<3, 1>(0, 3);
    r.errors.push_back((moved - dst.col(k)).norm());
    const TumPose& e = est[pairs[k].first];
    r.times.push_back(e.timestamp);
    // The aligned pose: position moved by the similarity, orientation by its rotation only.
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = R * to_iso(e).linear();
    T.translation() = moved;
    r.aligned.push_back(from_iso(e.timestamp, T));
  }
  r.trans = error_stats(r.errors);
  return r;
}

RpeResult compute_rpe(const Trajectory& est, const Trajectory& gt, double delta, const std::string& unit,
                      const EvalOptions& o) {
  if (unit != "frames" && unit != "seconds")
    throw Error("RPE delta unit must be 'frames' or 'seconds', not '" + unit + "'");
  if (!(delta > 0)) throw Error("RPE delta must be positive");
  const Pairs pairs = associated(est, gt, o, "RPE");
  double scale = 1.0;
  if (o.align == Alignment::sim3) {
    Eigen::Matrix3Xd src, dst;
    positions(est, gt, pairs, src, dst);
    scale = alignment(src, dst, Alignment::sim3).block<3, 1>(0, 0).norm();
  }
  auto est_pose = [&](std::size_t k) {
    Eigen::Isometry3d P = to_iso(est[pairs[k].first]);
    P.translation() *= scale;
    return P;
  };
  const std::size_t n = pairs.size();
  RpeResult r;
  for (std::size_t a = 0; a < n; ++a) {
    std::size_t b;
    if (unit == "frames") {
      b = a + static_cast<std::size_t>(std::llround(delta));
      if (b >= n) break;
    } else {
      // The pose closest in time to t_a + delta (ties to the earlier one); none when that is the
      // last pose, as in TUM's evaluate_rpe.py.
      const double target = est[pairs[a].first].timestamp + delta;
      b = a;
      while (b + 1 < n &&
             std::fabs(est[pairs[b + 1].first].timestamp - target) < std::fabs(est[pairs[b].first].timestamp - target))
        ++b;
      if (b == n - 1) continue;
    }
    const Eigen::Isometry3d Pa = est_pose(a), Pb = est_pose(b);
    const Eigen::Isometry3d Qa = to_iso(gt[pairs[a].second]), Qb = to_iso(gt[pairs[b].second]);
    const Eigen::Isometry3d P = Pa.inverse() * Pb, Q = Qa.inverse() * Qb;
    // Per frames E = Q^-1 P, the relative pose error of Sturm et al. 2012, eq. 1, as evo computes
    // it. Per seconds E = P Q^-1, what TUM's evaluate_rpe.py computes (its ominus composition):
    // the same rotation angle, a translation that differs by about the rotation error times the
    // distance moved, so the m/s figure is the one TUM's benchmark and papers report.
    const Eigen::Isometry3d E = unit == "frames" ? Q.inverse() * P : P * Q.inverse();
    r.trans_errors.push_back(E.translation().norm());
    r.rot_errors.push_back(rotation_angle_deg(E.linear()));
    r.times.push_back(est[pairs[a].first].timestamp);
  }
  if (r.trans_errors.empty())
    throw Error("RPE: no pose pairs " + std::to_string(delta) + " " + unit + " apart among " + std::to_string(n) +
                " associated poses");
  r.trans = error_stats(r.trans_errors);
  r.rot = error_stats(r.rot_errors);
  return r;
}

}  // namespace seamless
