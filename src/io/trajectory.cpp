#include "io/trajectory.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/output_file.hpp"
#include "io/tum_text.hpp"

namespace seamless {
namespace {

Eigen::Quaterniond quat(const TumPose& p) { return {p.q[3], p.q[0], p.q[1], p.q[2]}; }

void set_quat(TumPose& p, const Eigen::Quaterniond& q) {
  p.q[0] = q.x();
  p.q[1] = q.y();
  p.q[2] = q.z();
  p.q[3] = q.w();
}

using tum_text::where;

}  // namespace

SE3 TumPose::se3() const {
  Eigen::Matrix3d R = quat(*this).normalized().toRotationMatrix();
  SE3 T;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) T.R.m[r][c] = static_cast<float>(R(r, c));
  T.t = {static_cast<float>(t[0]), static_cast<float>(t[1]), static_cast<float>(t[2])};
  return T;
}

TumPose TumPose::from_se3(double timestamp, const SE3& T) {
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = T.R.m[r][c];
  // Project onto SO(3) first: a float rotation that drifted slightly still gives a unit quaternion.
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d Rn = svd.matrixU() * svd.matrixV().transpose();
  Eigen::Quaterniond q(Rn);
  if (q.w() < 0) q.coeffs() *= -1.0;  // one of the two equivalent signs, for stable files
  TumPose p;
  p.timestamp = timestamp;
  p.t[0] = T.t.x;
  p.t[1] = T.t.y;
  p.t[2] = T.t.z;
  set_quat(p, q.normalized());
  return p;
}

Trajectory read_tum_trajectory(const std::string& path) {
  Trajectory out;
  tum_text::for_each_data_line(path, "trajectory", [&](const std::string& line, int n) {
    std::istringstream ss(line);
    TumPose p;
    if (!(ss >> p.timestamp >> p.t[0] >> p.t[1] >> p.t[2] >> p.q[0] >> p.q[1] >> p.q[2] >> p.q[3]))
      throw InputError("malformed pose at " + where(path, n) + ": expected 'timestamp tx ty tz qx qy qz qw', got '" +
                       line + "'");
    double norm = quat(p).norm();
    if (!(norm > 0.9 && norm < 1.1))
      throw InputError("quaternion at " + where(path, n) + " has norm " + std::to_string(norm) +
                       ", expected 1 (order is qx qy qz qw)");
    set_quat(p, quat(p).normalized());
    if (!out.empty() && p.timestamp < out.back().timestamp)
      throw InputError("timestamps go backwards at " + where(path, n) + " (" + std::to_string(p.timestamp) + " after " +
                       std::to_string(out.back().timestamp) + "): sort the file by time");
    out.push_back(p);
  });
  return out;
}

void write_tum_trajectory(const std::string& path, const Trajectory& trajectory) {
  TrajectoryWriter w(path);
  for (const TumPose& p : trajectory) w.write(p);
  w.close();
}

std::optional<TumPose> interpolate_pose(const Trajectory& tr, double t, double max_gap) {
  auto it = std::lower_bound(tr.begin(), tr.end(), t, [](const TumPose& p, double v) { return p.timestamp < v; });
  if (it == tr.end()) return std::nullopt;
  if (it->timestamp == t) return *it;
  if (it == tr.begin()) return std::nullopt;
  const TumPose& a = *(it - 1);
  const TumPose& b = *it;
  if (b.timestamp - a.timestamp > max_gap) return std::nullopt;
  double s = (t - a.timestamp) / (b.timestamp - a.timestamp);
  TumPose p;
  p.timestamp = t;
  for (int i = 0; i < 3; ++i) p.t[i] = (1 - s) * a.t[i] + s * b.t[i];
  set_quat(p, quat(a).slerp(s, quat(b)).normalized());  // Eigen's slerp takes the short arc
  return p;
}

TrajectoryWriter::TrajectoryWriter(const std::string& path, const std::string& comment) : path_(path) {
  f_ = std::fopen(partial_path(path).c_str(), "w");
  if (!f_) throw Error("cannot create trajectory file '" + path + "': " + std::strerror(errno));
  if (!comment.empty()) std::fprintf(f_, "# %s\n", comment.c_str());
  std::fprintf(f_, "# timestamp tx ty tz qx qy qz qw\n");
}

TrajectoryWriter::~TrajectoryWriter() {
  try {
    close();
  } catch (const Error& e) {
    spdlog::error("{}", e.what());
  }
}

void TrajectoryWriter::close() {
  if (!f_) return;
  const bool ok = std::fclose(f_) == 0;
  f_ = nullptr;
  if (!ok) throw Error("cannot write trajectory file '" + path_ + "': " + std::strerror(errno));
  commit_partial(path_);
}

void TrajectoryWriter::write(const TumPose& p) {
  // 6 decimals for time (microseconds, as TUM) and 7 significant digits beyond metres (0.1 um).
  int n = std::fprintf(f_, "%.6f %.7f %.7f %.7f %.9f %.9f %.9f %.9f\n", p.timestamp, p.t[0], p.t[1], p.t[2], p.q[0],
                       p.q[1], p.q[2], p.q[3]);
  if (n < 0 || std::fflush(f_) != 0)
    throw Error("cannot write trajectory file '" + path_ + "': " + std::strerror(errno));
}

}  // namespace seamless
