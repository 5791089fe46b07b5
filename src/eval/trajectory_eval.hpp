// Trajectory accuracy with the TUM RGB-D benchmark's conventions (Sturm et al., IROS 2012), as
// TUM's evaluate_ate.py / evaluate_rpe.py and evo (Grupp 2017) compute them: association by
// nearest timestamp, ATE after a least-squares alignment (Umeyama 1991: SE(3), or Sim(3) with
// scale, or none), RPE over a fixed frame or time offset. Host code (Eigen).
// The functions take the estimate first (est, gt); `seamless eval` takes the files in the field's
// order, ground truth first.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "io/trajectory.hpp"

namespace seamless {

struct ErrorStats {
  double rmse = 0, mean = 0, median = 0, std = 0, min = 0, max = 0;  // std: population (as evo, numpy)
  std::size_t count = 0;
};
ErrorStats error_stats(std::vector<double> errors);

// How the estimate is moved onto the ground truth before ATE: the rigid motion (se3) or the
// similarity (sim3: rotation, translation and one scale, for monocular estimates) that minimises
// the squared position differences (Umeyama 1991, eq. 40-42), or not at all (none: both in the
// same world frame already).
enum class Alignment { se3, sim3, none };
Alignment parse_alignment(const std::string& name);  // "se3", "sim3", "none"; seamless::Error otherwise
const char* to_string(Alignment a);

struct EvalOptions {
  // Largest timestamp difference of an associated pair, seconds: TUM's associate.py default
  // (evo's is 0.01).
  double t_max_diff = 0.02;
  // Added to the estimate's timestamps before association (TUM's --offset, evo's --t_offset).
  double offset = 0.0;
  Alignment align = Alignment::se3;
};

// Pairs (estimate index, ground-truth index) whose timestamps (the estimate's plus offset)
// differ by at most max_dt, closest first, each pose used once (TUM's associate.py). Sorted by
// estimate time.
std::vector<std::pair<std::size_t, std::size_t>> associate(const Trajectory& est, const Trajectory& gt,
                                                           double max_dt = 0.02, double offset = 0.0);

struct AteResult {
  ErrorStats trans;            // metres, per associated pose
  std::vector<double> errors;  // per pair, in association order
  std::vector<double> times;   // estimate timestamps of the pairs
  Trajectory aligned;          // the estimate moved by the alignment (associated poses only)
  double R[3][3];              // the alignment: gt position = scale * R * est position + t
  double t[3];
  double scale = 1.0;  // 1 unless sim3
  Alignment align = Alignment::se3;
};
// Throws seamless::Error when fewer than 3 poses associate.
AteResult compute_ate(const Trajectory& est, const Trajectory& gt, const EvalOptions& o);
inline AteResult compute_ate(const Trajectory& est, const Trajectory& gt, double max_dt = 0.02) {
  return compute_ate(est, gt, EvalOptions{max_dt});
}

struct RpeResult {
  ErrorStats trans;  // metres per delta (per second: m/s)
  ErrorStats rot;    // degrees per delta (per second: deg/s)
  std::vector<double> trans_errors, rot_errors, times;
};
// RPE over the associated poses, P = P_i^-1 P_j (estimate), Q = Q_i^-1 Q_j (ground truth), each
// unit as the tool that offers it computes it:
//  - delta_unit "frames": every pair (i, i + delta), E = Q^-1 P (Sturm et al. 2012, eq. 1), as
//    evo_rpe -d N -u f;
//  - delta_unit "seconds": for each i the pose j closest in time to t_i + delta, pairs whose j
//    would be the last pose left out, E = P Q^-1: TUM's evaluate_rpe.py --fixed_delta
//    --delta_unit s (its pairing, which drops the pairs that would run past the end, and its
//    composition; evo has no time delta). With delta 1 s the errors are m/s and deg/s, the
//    figures TUM's benchmark and papers report for odometry.
// Translation error |t(E)|, rotation error the angle of E (the same for both compositions).
// With o.align sim3 the estimate's translations are first scaled by the Sim(3) alignment's scale
// (evo_rpe -as); se3 and none leave RPE unchanged (it is invariant to a rigid motion of either
// trajectory). Throws seamless::Error when no pair is delta apart.
RpeResult compute_rpe(const Trajectory& est, const Trajectory& gt, double delta, const std::string& delta_unit,
                      const EvalOptions& o);
inline RpeResult compute_rpe(const Trajectory& est, const Trajectory& gt, double delta, const std::string& delta_unit,
                             double max_dt = 0.02) {
  return compute_rpe(est, gt, delta, delta_unit, EvalOptions{max_dt});
}

}  // namespace seamless
