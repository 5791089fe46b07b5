// Trajectory accuracy with the TUM RGB-D benchmark's conventions (Sturm et al., IROS 2012):
// association by nearest timestamp, ATE after a rigid alignment (Horn 1987 / Umeyama 1991, no
// scale), RPE over a fixed frame or time offset. Host code (Eigen).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "io/trajectory.hpp"

namespace seamless {

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;
  std::size_t count = 0;
};
ErrorStats error_stats(std::vector<double> errors);

// Pairs (estimate index, ground-truth index) whose timestamps differ by at most max_dt, closest
// first, each pose used once (TUM's associate.py). Sorted by estimate time.
std::vector<std::pair<std::size_t, std::size_t>> associate(const Trajectory& est, const Trajectory& gt,
                                                           double max_dt = 0.02);

struct AteResult {
  ErrorStats trans;                  // metres, per associated pose
  std::vector<double> errors;        // per pair, in association order
  std::vector<double> times;         // estimate timestamps of the pairs
  Trajectory aligned;                // the estimate moved by the alignment (associated poses only)
  double R[3][3];                    // gt_T_est rotation of the alignment
  double t[3];
};
// Throws seamless::Error when fewer than 3 poses associate.
AteResult compute_ate(const Trajectory& est, const Trajectory& gt, double max_dt = 0.02);

struct RpeResult {
  ErrorStats trans;  // metres per delta
  ErrorStats rot;    // degrees per delta
  std::vector<double> trans_errors, rot_errors, times;
};
// delta in frames (delta_unit "frames": pairs i, i+delta of the associated sequence) or seconds
// ("seconds": for each i the first j with t_j - t_i >= delta).
RpeResult compute_rpe(const Trajectory& est, const Trajectory& gt, double delta, const std::string& delta_unit,
                      double max_dt = 0.02);

}  // namespace seamless
