#include "recon/refine/refine.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/log.hpp"
#include "core/output_file.hpp"
#include "core/progress.hpp"
#include "io/input_params.hpp"
#include "kernels/recon/rgbd.hpp"
#include "recon/preprocess.hpp"
#include "recon/refine/refine_graph.hpp"
#include "recon/refine/refine_steps.hpp"
#include "recon/tracker.hpp"
#include "seamless/build_config.hpp"

namespace seamless {

// The steps are shared with the online refinement (online_refine.cpp): refine_steps.hpp.
namespace refine_detail {
namespace {
constexpr double kRadToDeg = 57.29577951308232;
}  // namespace

Pose to_pose(const TumPose& p) {
  Pose o;
  o.q = Eigen::Quaterniond(p.q[3], p.q[0], p.q[1], p.q[2]).normalized();
  o.t = {p.t[0], p.t[1], p.t[2]};
  return o;
}

TumPose to_tum(double timestamp, const Pose& p) {
  TumPose o;
  o.timestamp = timestamp;
  Eigen::Quaterniond q = p.q.normalized();
  if (q.w() < 0) q.coeffs() *= -1.0;
  o.q[0] = q.x(), o.q[1] = q.y(), o.q[2] = q.z(), o.q[3] = q.w();
  o.t[0] = p.t.x(), o.t[1] = p.t.y(), o.t[2] = p.t.z();
  return o;
}

SE3 to_se3(const Pose& p) { return to_tum(0.0, p).se3(); }
Pose from_se3(const SE3& T) { return to_pose(TumPose::from_se3(0.0, T)); }

double angle_deg(const Eigen::Quaterniond& q) { return 2.0 * std::acos(std::min(1.0, std::abs(q.w()))) * kRadToDeg; }

// Rotation (degrees) and translation (metres) of b relative to a.
std::pair<double, double> distance(const Pose& a, const Pose& b) {
  Pose d = refine_detail::compose(refine_detail::inverse(a), b);
  return {angle_deg(d.q), d.t.norm()};
}

bool is_tracked(const std::vector<bool>& tracked, std::size_t i) { return tracked.empty() || tracked[i]; }

bool keyframe_due(const Pose& last_keyframe, std::int64_t last_index, const Pose& pose, std::int64_t index,
                  const RefineParams& p) {
  if (p.keyframes == KeyframeRule::every) return index - last_index >= p.keyframe_every;
  auto [deg, m] = distance(last_keyframe, pose);
  return m > p.keyframe_translation || deg > p.keyframe_rotation_deg;
}
}  // namespace refine_detail

using namespace refine_detail;

bool refine_available() { return SEAMLESS_HAS_CERES != 0; }

void require_refine(const RefineParams& params) {
  if ((params.enabled || params.online) && !refine_available())
    throw ConfigError(std::string("refine.") + (params.enabled ? "enabled" : "online") +
                      " is true but this build has no Ceres: install libceres-dev and build seamless again, or set it "
                      "to false");
}

// ---- keyframes ----------------------------------------------------------------------------------

std::vector<std::int64_t> select_keyframes(const Trajectory& odometry, const RefineParams& p,
                                           const std::vector<bool>& tracked) {
  if (!tracked.empty() && tracked.size() != odometry.size())
    throw Error("refine: " + std::to_string(tracked.size()) + " tracking flags for " + std::to_string(odometry.size()) +
                " poses");
  std::vector<std::int64_t> kf;
  for (std::size_t i = 0; i < odometry.size(); ++i) {
    if (!is_tracked(tracked, i)) continue;  // a lost frame carries the last good pose, not its own
    if (kf.empty()) {
      kf.push_back(static_cast<std::int64_t>(i));
      continue;
    }
    const std::int64_t last = kf.back();
    if (keyframe_due(to_pose(odometry[last]), last, to_pose(odometry[i]), static_cast<std::int64_t>(i), p))
      kf.push_back(static_cast<std::int64_t>(i));
  }
  // The sequence's end is anchored by a keyframe, so no frame is left to extrapolation only.
  for (std::size_t i = odometry.size(); i-- > 0;) {
    if (!is_tracked(tracked, i)) continue;
    if (!kf.empty() && kf.back() != static_cast<std::int64_t>(i) &&
        static_cast<std::int64_t>(i) - kf.back() >= std::max(1, p.keyframe_every / 2))
      kf.push_back(static_cast<std::int64_t>(i));
    break;
  }
  return kf;
}

// ---- keyframe images ----------------------------------------------------------------------------

namespace refine_detail {

std::unique_ptr<FramePyramid> build_pyramid(const RgbdFrame& f, const Intrinsics& K, const PreprocessParams& pre,
                                            bool colour, Device d) {
  auto pyr = std::make_unique<FramePyramid>(d, K, pre.levels);
  Image<float> depth = f.depth.clone(d);
  Image<float> intensity;
  bool has_rgb = colour && f.rgb.width() == f.depth.width() && f.rgb.height() == f.depth.height();
  if (has_rgb) {
    Image<uchar3> rgb = f.rgb.clone(d);
    intensity = Image<float>(K.width, K.height, d);
    with_exec(d, [&]<class E>(const E& ex) { kernels::Rgbd<E>::rgb_to_intensity(ex, rgb.cview(), intensity.view()); });
  }
  pyr->build(depth, has_rgb ? &intensity : nullptr, pre);
  return pyr;
}

namespace {
// Reads the whole source (its frames are the trajectory's, in order) and keeps the keyframes.
std::vector<KeyframeData> load_keyframes(FrameSource& source, const Trajectory& odometry,
                                         const std::vector<std::int64_t>& kf, const PreprocessParams& pre, bool colour,
                                         Device d) {
  std::vector<KeyframeData> out;
  const Intrinsics K = source.intrinsics();
  RgbdFrame f;
  std::int64_t n = 0;
  std::size_t next = 0;
  const auto total = static_cast<std::int64_t>(odometry.size());
  Progress progress("refine: reading the keyframes", total);
  while (n < total && source.next(f)) {
    if (next < kf.size() && n == kf[next]) {
      out.push_back({n, odometry[n].timestamp, to_pose(odometry[n]), build_pyramid(f, K, pre, colour, d)});
      ++next;
    }
    progress.update(++n);
  }
  progress.finish();
  if (n != total)
    throw InputError("refine: the source '" + source.name() + "' gave " + std::to_string(n) +
                     " frames but the trajectory has " + std::to_string(total) +
                     " poses; refine the trajectory of exactly these frames (same input, same frames setting)");
  return out;
}

}  // namespace

// ---- pairwise alignment -------------------------------------------------------------------------

// The pairwise tracker: frame to frame, and no loss tests of its own (align_pair applies the
// refinement's tests at the level it uses).
TrackerParams pair_tracker_params(const RefineParams& p) {
  TrackerParams t;
  t.kind = enum_name(p.pair_tracker);
  t.mode = TrackingMode::frame_to_frame;
  t.iterations = p.iterations;
  t.photometric_weight = p.photometric_weight;
  t.weighting = p.weighting;
  t.depth_noise = p.depth_noise;
  t.photometric_pixels = p.photometric_pixels;
  t.min_inlier_ratio = 0.f;
  t.min_inlier_ratio_vs_last = 0.f;
  t.max_condition = 1e300;
  t.max_translation_jump = 1e6f;
  t.max_rotation_jump_deg = 180.f;
  return t;
}

// The finest level the alignment iterates on: where the edge's statistics and information come from.
int finest_level(const RefineParams& p, int levels) {
  for (int l = 0; l < std::min<int>(levels, static_cast<int>(p.iterations.size())); ++l)
    if (p.iterations[l] > 0) return l;
  throw ConfigError("refine.iterations has no level with iterations > 0: the pairwise alignment would do nothing");
}

namespace {
struct PairResult {
  bool ok = false;
  Pose z;  // i_T_j
  Eigen::Matrix<double, 6, 6> info = Eigen::Matrix<double, 6, 6>::Zero();
  double inlier_ratio = 0;
  std::string why;  // when rejected
};

// Lambda = J^T J / sigma^2 * (samples / inliers): the Gauss-Newton information of the alignment
// (Kerl et al. 2013, sec. IV-B: the inverse Hessian as the edge covariance), with the per-residual
// variance sigma^2 = error / inliers, scaled from `inliers` correlated pixels to
// refine.information_samples independent ones (neighbouring pixels share filter support and
// calibration error, so N pixels are not N observations).
Eigen::Matrix<double, 6, 6> information(const kernels::IcpSums& s, const RefineParams& p) {
  Eigen::Matrix<double, 6, 6> A;
  int k = 0;
  for (int r = 0; r < 6; ++r)
    for (int c = r; c < 6; ++c) A(r, c) = A(c, r) = s.jtj[k++];
  const double sigma2 = std::max(s.error / std::max(s.inliers, 1.0), 1e-12);
  return A / sigma2 * (p.information_samples / std::max(s.inliers, 1.0));
}

PairResult align_pair(const Tracker& tracker, const KeyframeData& a, const KeyframeData& b, ReferenceMaps& ref_a,
                      const RefineParams& p, int level) {
  PairResult out;
  const Pose z_odo = refine_detail::compose(refine_detail::inverse(a.odometry), b.odometry);
  // In a's frame (world_T_ref = identity): the estimate is i_T_j directly.
  TrackResult r = tracker.track(*b.pyr, ref_a, to_se3(z_odo));
  out.z = from_se3(r.world_T_camera);
  kernels::IcpSums s = tracker.reduce(*b.pyr, ref_a, level, r.world_T_camera);
  out.inlier_ratio = s.valid > 0 ? s.inliers / s.valid : 0.0;
  IcpStep step = solve_icp_step(s);
  auto [deg, m] = distance(z_odo, out.z);
  if (r.status == TrackStatus::degenerate || !step.solved || step.condition > 1e6) out.why = "degenerate";
  else if (out.inlier_ratio < p.min_pair_inlier_ratio) out.why = "inliers";
  else if (m > p.max_pair_correction || deg > p.max_pair_correction_deg) out.why = "correction";
  else out.ok = true;
  if (out.ok) out.info = information(s, p);
  return out;
}
}  // namespace

// Overlap of b with a at the odometry's relative pose: the share of b's pixels (coarsest level)
// that find a correspondence on a's surface.
double overlap(const Tracker& tracker, const KeyframeData& a, const KeyframeData& b, const ReferenceMaps& ref_a) {
  const Pose z_odo = refine_detail::compose(refine_detail::inverse(a.odometry), b.odometry);
  kernels::IcpSums s = tracker.reduce(*b.pyr, ref_a, ref_a.levels() - 1, to_se3(z_odo));
  return s.valid > 0 ? s.inliers / s.valid : 0.0;
}

// Odometry edge (consecutive keyframes a, b): the tracker's relative pose. It is a chain of n =
// b - a per-frame alignments, so (errors of a random walk) its covariance is about n times that of
// one direct alignment of the pair: its information is odometry_weight / n times the information
// of the pair's alignment evaluated at the odometry's pose.
void add_odometry_edge(Graph& g, const Tracker& tracker, const KeyframeData& a, const KeyframeData& b,
                       const ReferenceMaps& ref_a, int i, const RefineParams& p, int level) {
  if (p.odometry_weight <= 0) return;
  const Pose z_odo = refine_detail::compose(refine_detail::inverse(a.odometry), b.odometry);
  kernels::IcpSums s = tracker.reduce(*b.pyr, ref_a, level, to_se3(z_odo));
  const double n = static_cast<double>(std::max<std::int64_t>(1, b.frame - a.frame));
  Eigen::Matrix<double, 6, 6> info = information(s, p) * (p.odometry_weight / n);
  if (s.inliers < 6 || !solve_icp_step(s).solved) {
    // Nothing to weigh it by (the views barely overlap): a weak isotropic prior, 1 cm / 1 degree,
    // keeps the chain connected without pretending to know the motion.
    info = Eigen::Matrix<double, 6, 6>::Identity();
    info.topLeftCorner<3, 3>() *= 1.0 / std::pow(1.0 / kRadToDeg, 2);
    info.bottomRightCorner<3, 3>() *= 1.0 / std::pow(0.01, 2);
  }
  g.edges.push_back({i, i + 1, z_odo, info, false, true});
  ++g.stats.odometry_edges;
}

void add_pair_edge(Graph& g, const Tracker& tracker, const KeyframeData& a, const KeyframeData& b, ReferenceMaps& ref_a,
                   int i, int j, const RefineParams& p, int level) {
  PairResult r = align_pair(tracker, a, b, ref_a, p, level);
  if (!r.ok) {
    ++g.stats.rejected_pairs;
    spdlog::debug("refine: pair {}-{} rejected ({}, inliers {:.2f})", a.frame, b.frame, r.why, r.inlier_ratio);
    return;
  }
  g.edges.push_back({i, j, r.z, r.info, j != i + 1, false});
  ++g.stats.pair_edges;
}

// Candidate partners of keyframe i among the later ones: close in the odometry (pose distance),
// then overlapping (projective test), the most overlapping max_pairs_per_keyframe of them.
std::vector<int> partners(const Tracker& tracker, const std::vector<KeyframeData>& kf, const ReferenceMaps& ref_i,
                          int i, const RefineParams& p) {
  std::vector<std::pair<double, int>> cand;
  for (int j = i + 2; j < static_cast<int>(kf.size()); ++j) {
    auto [deg, m] = distance(kf[i].odometry, kf[j].odometry);
    if (m > p.max_pair_translation || deg > p.max_pair_rotation_deg) continue;
    double ov = overlap(tracker, kf[i], kf[j], ref_i);
    if (ov >= p.min_overlap) cand.push_back({ov, j});
  }
  return best_partners(std::move(cand), p);
}

std::vector<int> best_partners(std::vector<std::pair<double, int>> cand, const RefineParams& p) {
  std::sort(cand.begin(), cand.end(), [](auto& x, auto& y) { return x.first > y.first; });
  if (static_cast<int>(cand.size()) > p.max_pairs_per_keyframe) cand.resize(p.max_pairs_per_keyframe);
  std::vector<int> out;
  for (auto& c : cand) out.push_back(c.second);
  return out;
}

Graph build_graph(const std::vector<KeyframeData>& kf, const RefineParams& p, Device d) {
  Graph g;
  Tracker tracker(pair_tracker_params(p), d);
  const int level = finest_level(p, kf.front().pyr->levels());
  ReferenceMaps ref;
  Progress progress("refine: aligning keyframe pairs", static_cast<std::int64_t>(kf.size()) - 1, true, "keyframes/s");
  for (int i = 0; i + 1 < static_cast<int>(kf.size()); ++i) {
    ref.set_from_frame(*kf[i].pyr, SE3::identity());
    add_odometry_edge(g, tracker, kf[i], kf[i + 1], ref, i, p, level);
    add_pair_edge(g, tracker, kf[i], kf[i + 1], ref, i, i + 1, p, level);
    std::vector<int> js = partners(tracker, kf, ref, i, p);
    g.stats.candidate_pairs += static_cast<std::int64_t>(js.size());
    for (int j : js) add_pair_edge(g, tracker, kf[i], kf[j], ref, i, j, p, level);
    progress.update(i + 1);
  }
  return g;
}

// ---- corrections --------------------------------------------------------------------------------

// Every pose follows the keyframes around it: its odometry relative to the keyframe before (a) and
// after (b) is kept, applied to each refined keyframe, and the two results are blended by the
// time between them (the correction of the drift is spread evenly over the interval, as the
// deformation of ElasticFusion, Whelan et al. 2015, spreads a loop closure along the trajectory).
Trajectory apply_corrections(const Trajectory& odometry, const std::vector<KeyframeData>& kf,
                             const std::vector<Pose>& refined) {
  Trajectory out(odometry.size());
  std::size_t b = 0;
  for (std::size_t f = 0; f < odometry.size(); ++f) {
    while (b < kf.size() && kf[b].frame < static_cast<std::int64_t>(f)) ++b;
    const Pose odo = to_pose(odometry[f]);
    auto via = [&](std::size_t k) {
      return refine_detail::compose(refined[k], refine_detail::compose(refine_detail::inverse(kf[k].odometry), odo));
    };
    Pose p;
    if (b == 0) p = via(0);                           // before the first keyframe
    else if (b == kf.size()) p = via(kf.size() - 1);  // after the last
    else if (kf[b].frame == static_cast<std::int64_t>(f)) p = refined[b];
    else {
      const double ta = kf[b - 1].timestamp, tb = kf[b].timestamp;
      const double alpha = tb > ta ? std::clamp((odometry[f].timestamp - ta) / (tb - ta), 0.0, 1.0) : 0.5;
      p = refine_detail::blend(via(b - 1), via(b), alpha);
    }
    out[f] = to_tum(odometry[f].timestamp, p);
  }
  return out;
}

}  // namespace refine_detail

namespace {
RefineResult no_op(const Trajectory& odometry, RefineResult r, const std::string& why) {
  r.trajectory = odometry;
  r.stats.message = why;
  spdlog::warn("refine: {}; the trajectory is left as tracked", why);
  return r;
}

}  // namespace

RefineResult refine_trajectory(FrameSource& source, const Trajectory& odometry, const RefineParams& params,
                               const PreprocessParams& preprocess, Device device, const std::vector<bool>& tracked) {
  const auto t0 = std::chrono::steady_clock::now();
  RefineResult r;
  r.stats.frames = static_cast<std::int64_t>(odometry.size());
  r.keyframes = select_keyframes(odometry, params, tracked);
  r.stats.keyframes = static_cast<std::int64_t>(r.keyframes.size());
  if (r.keyframes.size() < 2)
    return no_op(odometry, r,
                 "fewer than two keyframes (" + std::to_string(odometry.size()) + " frames, refine.keyframe_every " +
                     std::to_string(params.keyframe_every) + ")");
  if (!refine_available())
    throw ConfigError("refine: this build has no Ceres; install libceres-dev and build seamless again");
  std::vector<KeyframeData> kf =
      load_keyframes(source, odometry, r.keyframes, preprocess, params.pair_tracker == PairTracker::rgbd, device);
  const double t_load = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  Graph g = build_graph(kf, params, device);
  const double t_graph = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - t_load;
  const RefineStats counts = g.stats;
  r.stats.candidate_pairs = counts.candidate_pairs;
  r.stats.pair_edges = counts.pair_edges;
  r.stats.rejected_pairs = counts.rejected_pairs;
  r.stats.odometry_edges = counts.odometry_edges;
  if (r.stats.pair_edges == 0)
    return no_op(odometry, r,
                 "no keyframe pair could be aligned (no overlap within refine.max_pair_* and "
                 "refine.min_overlap, or every alignment was rejected)");
  std::vector<Pose> initial;
  for (const KeyframeData& k : kf) initial.push_back(k.odometry);
  refine_detail::GraphSolution sol = refine_detail::solve_pose_graph(initial, g.edges, params);
  for (std::size_t k = 0; k < kf.size(); ++k) {
    auto [deg, m] = distance(initial[k], sol.poses[k]);
    r.stats.max_correction_deg = std::max(r.stats.max_correction_deg, deg);
    r.stats.max_correction_m = std::max(r.stats.max_correction_m, m);
  }
  r.trajectory = apply_corrections(odometry, kf, sol.poses);
  r.stats.iterations = sol.iterations;
  r.stats.initial_cost = sol.initial_cost;
  r.stats.final_cost = sol.final_cost;
  r.stats.converged = sol.converged;
  r.stats.message = sol.message;
  r.stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const RefineStats& s = r.stats;
  spdlog::info(
      "refine: {} keyframes, {} pair edges ({} loop candidates, {} rejected), {} odometry edges; Ceres {} "
      "iterations, cost {:.4g} -> {:.4g}; largest keyframe correction {:.1f} mm / {:.2f} deg; {:.1f} s "
      "({:.1f} s reading and preprocessing the keyframes, {:.1f} s aligning pairs)",
      s.keyframes, s.pair_edges, s.candidate_pairs, s.rejected_pairs, s.odometry_edges, s.iterations, s.initial_cost,
      s.final_cost, s.max_correction_m * 1e3, s.max_correction_deg, s.seconds, t_load, t_graph);
  return r;
}

void write_refine_stats(const std::string& path, const RefineStats& s) {
  std::FILE* f = std::fopen(partial_path(path).c_str(), "w");
  if (!f)
    throw Error("cannot write refinement statistics '" + path + "': check that the folder exists and is writable");
  std::fprintf(f,
               "key,value\nframes,%lld\nkeyframes,%lld\ncandidate_pairs,%lld\npair_edges,%lld\n"
               "rejected_pairs,%lld\nodometry_edges,%lld\niterations,%d\ninitial_cost,%.9g\nfinal_cost,%.9g\n"
               "converged,%d\nmax_correction_m,%.6f\nmax_correction_deg,%.4f\nseconds,%.3f\nmessage,\"%s\"\n",
               static_cast<long long>(s.frames), static_cast<long long>(s.keyframes),
               static_cast<long long>(s.candidate_pairs), static_cast<long long>(s.pair_edges),
               static_cast<long long>(s.rejected_pairs), static_cast<long long>(s.odometry_edges), s.iterations,
               s.initial_cost, s.final_cost, s.converged ? 1 : 0, s.max_correction_m, s.max_correction_deg, s.seconds,
               s.message.c_str());
  if (std::fclose(f) != 0) throw Error("error writing refinement statistics '" + path + "' (disk full?)");
  commit_partial(path);
}

RefineResult refine_run(const InputParams& input, const Trajectory& odometry, const std::vector<bool>& tracked,
                        const RefineParams& params, const PreprocessParams& preprocess, Device device,
                        const std::string& out_dir) {
  require_refine(params);
  const std::string traj = out_dir + "/trajectory.txt", odo = out_dir + "/trajectory_odometry.txt";
  if (std::filesystem::exists(traj)) std::filesystem::rename(traj, odo);
  else write_tum_trajectory(odo, odometry);
  auto source = make_source(input, device);
  RefineResult r = refine_trajectory(*source, odometry, params, preprocess, device, tracked);
  write_tum_trajectory(traj, r.trajectory);
  write_refine_stats(out_dir + "/refine_stats.csv", r.stats);
  spdlog::info("refine: trajectory.txt is the refined trajectory, trajectory_odometry.txt the tracker's");
  return r;
}

}  // namespace seamless
