#include "recon/refine/online_refine.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "core/error.hpp"
#include "core/log.hpp"
#include "core/output_file.hpp"
#include "core/timing.hpp"
#include "recon/refine/refine_steps.hpp"

namespace seamless {

using namespace refine_detail;

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

RgbdFrame host_copy(const RgbdFrame& f) {
  RgbdFrame c;
  c.index = f.index, c.timestamp = f.timestamp, c.intrinsics = f.intrinsics;
  if (f.depth.width() > 0) c.depth = f.depth.clone(Device::CPU);
  if (f.rgb.width() > 0) c.rgb = f.rgb.clone(Device::CPU);
  return c;
}

double max_of(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }
double median_of(const std::vector<double>& v) { return v.empty() ? 0.0 : median(v); }
}  // namespace

// ---- OnlineRefiner (background) -----------------------------------------------------------------

OnlineRefiner::OnlineRefiner(const RefineParams& params, const PreprocessParams& preprocess, const Intrinsics& K)
    : p_(params), pre_(preprocess), K_(K), graph_(std::make_unique<Graph>()) {
  require_refine(RefineParams{.enabled = true});  // names libceres-dev when this build has no Ceres
  thread_ = std::thread([this] { run(); });
}

OnlineRefiner::~OnlineRefiner() {
  {
    std::lock_guard<std::mutex> l(queue_m_);
    stop_ = true;
    queue_.clear();
  }
  queue_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void OnlineRefiner::submit(std::int64_t frame_index, double timestamp, const SE3& odometry, RgbdFrame frame) {
  {
    std::lock_guard<std::mutex> l(queue_m_);
    if (stop_) throw Error("online refinement: a keyframe was handed over after finish()");
    queue_.push_back({frame_index, timestamp, odometry, std::move(frame)});
  }
  queue_cv_.notify_one();
}

std::shared_ptr<const OnlineSolution> OnlineRefiner::latest() const {
  std::lock_guard<std::mutex> l(solution_m_);
  return latest_;
}

void OnlineRefiner::finish() {
  {
    std::lock_guard<std::mutex> l(queue_m_);
    stop_ = true;  // run() still empties the queue before it returns
  }
  queue_cv_.notify_all();
  if (thread_.joinable()) thread_.join();
}

OnlineRefineStats OnlineRefiner::stats() const {
  std::lock_guard<std::mutex> l(stats_m_);
  return stats_;
}

std::string OnlineRefiner::last_message() const {
  std::lock_guard<std::mutex> l(stats_m_);
  return message_;
}

// The worker: every keyframe waiting is added to the graph (its edges aligned), then the graph is
// solved once; a worker that falls behind solves less often, never holds the tracking thread.
void OnlineRefiner::run() {
  // One OpenMP thread for the pairwise alignments: the tracking thread keeps the other cores.
  omp_set_num_threads(1);
  for (;;) {
    std::deque<Item> batch;
    {
      std::unique_lock<std::mutex> l(queue_m_);
      queue_cv_.wait(l, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;  // stopped, nothing left
      batch.swap(queue_);
    }
    try {
      for (Item& it : batch) add_keyframe(it);
      solve();
    } catch (const std::exception& e) {
      // A failed alignment or solve costs this update, not the run: the tracker keeps the last
      // solution, the next keyframe tries again.
      spdlog::warn("online refinement: {}", e.what());
      std::lock_guard<std::mutex> l(stats_m_);
      message_ = e.what();
    }
  }
}

// The new keyframe j's edges, as the offline graph has them (refine_steps.hpp): the odometry edge
// and the alignment with keyframe j-1, and alignments with the max_pairs_per_keyframe most
// overlapping older keyframes close enough in the odometry (the offline stage picks each keyframe's
// partners among the later ones, the online one among the earlier ones: the only difference).
void OnlineRefiner::add_keyframe(Item& it) {
  const auto t0 = std::chrono::steady_clock::now();
  KeyframeData k;
  k.frame = it.frame, k.timestamp = it.timestamp, k.odometry = from_se3(it.odometry);
  k.pyr = build_pyramid(it.images, K_, pre_, p_.pair_tracker == PairTracker::rgbd, Device::CPU);
  it.images = RgbdFrame();
  kf_.push_back(std::move(k));
  const int j = static_cast<int>(kf_.size()) - 1;
  if (j == 0) {
    refined_.push_back(it.odometry);
  } else {
    // Its first estimate: the previous keyframe's refined pose and the odometry since.
    refined_.push_back(
        to_se3(compose(from_se3(refined_[j - 1]), compose(inverse(kf_[j - 1].odometry), kf_[j].odometry))));
    Tracker tracker(pair_tracker_params(p_), Device::CPU);
    const int level = finest_level(p_, kf_[j].pyr->levels());
    Graph& g = *graph_;
    ReferenceMaps ref;
    ref.set_from_frame(*kf_[j - 1].pyr, SE3::identity());
    add_odometry_edge(g, tracker, kf_[j - 1], kf_[j], ref, j - 1, p_, level);
    add_pair_edge(g, tracker, kf_[j - 1], kf_[j], ref, j - 1, j, p_, level);
    std::vector<std::pair<double, int>> cand;
    for (int i = 0; i + 1 < j; ++i) {
      auto [deg, m] = distance(kf_[i].odometry, kf_[j].odometry);
      if (m > p_.max_pair_translation || deg > p_.max_pair_rotation_deg) continue;
      ref.set_from_frame(*kf_[i].pyr, SE3::identity());
      const double ov = overlap(tracker, kf_[i], kf_[j], ref);
      if (ov >= p_.min_overlap) cand.push_back({ov, i});
    }
    const std::vector<int> partners = best_partners(std::move(cand), p_);
    g.stats.candidate_pairs += static_cast<std::int64_t>(partners.size());
    for (int i : partners) {
      ref.set_from_frame(*kf_[i].pyr, SE3::identity());
      add_pair_edge(g, tracker, kf_[i], kf_[j], ref, i, j, p_, level);
    }
  }
  std::lock_guard<std::mutex> l(stats_m_);
  ++stats_.keyframes;
  stats_.keyframe_s.push_back(seconds_since(t0));
}

// Ceres over the whole graph from the current estimates (the last solution, the new keyframes
// chained on by odometry): a few iterations when little changed. Published for latest().
void OnlineRefiner::solve() {
  const RefineStats counts = graph_->stats;
  {
    std::lock_guard<std::mutex> l(stats_m_);
    stats_.candidate_pairs = counts.candidate_pairs, stats_.pair_edges = counts.pair_edges;
    stats_.rejected_pairs = counts.rejected_pairs, stats_.odometry_edges = counts.odometry_edges;
  }
  if (counts.pair_edges == 0) return;  // nothing beyond the odometry yet: no correction to publish
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<Pose> initial;
  for (const SE3& T : refined_) initial.push_back(from_se3(T));
  GraphSolution sol = solve_pose_graph(initial, graph_->edges, p_);
  auto out = std::make_shared<OnlineSolution>();
  double max_m = 0, max_deg = 0;
  for (std::size_t k = 0; k < kf_.size(); ++k) {
    refined_[k] = to_se3(sol.poses[k]);
    out->frames.push_back(kf_[k].frame);
    out->odometry.push_back(to_se3(kf_[k].odometry));
    out->refined.push_back(refined_[k]);
    auto [deg, m] = distance(kf_[k].odometry, sol.poses[k]);
    max_m = std::max(max_m, m), max_deg = std::max(max_deg, deg);
  }
  {
    std::lock_guard<std::mutex> l(stats_m_);
    ++stats_.solves;
    stats_.solve_s.push_back(seconds_since(t0));
    stats_.max_correction_m = max_m, stats_.max_correction_deg = max_deg;
    message_ = sol.message;
    out->version = stats_.solves;
  }
  std::lock_guard<std::mutex> l(solution_m_);
  latest_ = std::move(out);
}

Trajectory OnlineRefiner::corrected(const Trajectory& odometry) const {
  if (kf_.empty()) return odometry;
  std::vector<Pose> refined;
  for (const SE3& T : refined_) refined.push_back(from_se3(T));
  return apply_corrections(odometry, kf_, refined);
}

// ---- OnlineCorrector (tracking thread) ----------------------------------------------------------

bool online_feedback(const TrackerParams& tracker) {
  return !(tracker.mode == TrackingMode::frame_to_model && (tracker.kind == "icp" || tracker.kind == "rgbd"));
}

OnlineCorrector::OnlineCorrector(const RefineParams& params, const PreprocessParams& preprocess, const Intrinsics& K,
                                 bool feedback)
    : p_(params), feedback_(feedback), refiner_(params, preprocess, K) {}

std::optional<SE3> OnlineCorrector::after_frame(const RgbdFrame& frame, const FrameRecord& rec) {
  const auto t0 = std::chrono::steady_clock::now();
  // The pose in the odometry's own frame: the corrections applied so far taken back out.
  const SE3 odo = correction_.inverse() * rec.result.world_T_camera;
  odometry_.push_back(TumPose::from_se3(frame.timestamp, odo));
  const auto index = static_cast<std::int64_t>(odometry_.size()) - 1;
  if (rec.result.ok() &&  // lost frames are never keyframes (they carry the last good pose)
      (!last_keyframe_ ||
       keyframe_due(from_se3(last_keyframe_->second), last_keyframe_->first, from_se3(odo), index, p_))) {
    refiner_.submit(index, frame.timestamp, odo, host_copy(frame));
    last_keyframe_ = std::make_pair(index, odo);
  }
  std::optional<SE3> delta;
  if (std::shared_ptr<const OnlineSolution> s = refiner_.latest(); s && s->version != seen_version_) {
    seen_version_ = s->version;
    // The newest solved keyframe's correction; the tracker's pose follows it from now on.
    const SE3 c = s->refined.back() * s->odometry.back().inverse();
    if (feedback_) {
      delta = c * correction_.inverse();
      correction_ = c;
      ++corrections_;
    }
  }
  handover_ms_.push_back(1e3 * seconds_since(t0));
  return delta;
}

Trajectory OnlineCorrector::finish() {
  const auto t0 = std::chrono::steady_clock::now();
  refiner_.finish();
  final_wait_s_ = seconds_since(t0);
  return refiner_.corrected(odometry_);
}

OnlineRefineStats OnlineCorrector::stats() const {
  OnlineRefineStats s = refiner_.stats();
  s.corrections = corrections_;
  s.handover_ms = handover_ms_;
  s.final_wait_s = final_wait_s_;
  return s;
}

// ---- outputs ------------------------------------------------------------------------------------

void write_online_stats(const std::string& path, const OnlineRefineStats& s) {
  std::FILE* f = std::fopen(partial_path(path).c_str(), "w");
  if (!f) throw Error("cannot write online refinement statistics '" + path + "': check that the folder is writable");
  std::fprintf(f,
               "key,value\nkeyframes,%lld\nsolves,%lld\ncorrections,%lld\ncandidate_pairs,%lld\npair_edges,%lld\n"
               "rejected_pairs,%lld\nodometry_edges,%lld\nmax_correction_m,%.6f\nmax_correction_deg,%.4f\n"
               "handover_ms_median,%.4f\nhandover_ms_max,%.4f\nkeyframe_s_median,%.4f\nkeyframe_s_max,%.4f\n"
               "solve_s_median,%.5f\nsolve_s_max,%.5f\nfinal_wait_s,%.3f\n",
               static_cast<long long>(s.keyframes), static_cast<long long>(s.solves),
               static_cast<long long>(s.corrections), static_cast<long long>(s.candidate_pairs),
               static_cast<long long>(s.pair_edges), static_cast<long long>(s.rejected_pairs),
               static_cast<long long>(s.odometry_edges), s.max_correction_m, s.max_correction_deg,
               median_of(s.handover_ms), max_of(s.handover_ms), median_of(s.keyframe_s), max_of(s.keyframe_s),
               median_of(s.solve_s), max_of(s.solve_s), s.final_wait_s);
  if (std::fclose(f) != 0) throw Error("error writing online refinement statistics '" + path + "' (disk full?)");
  commit_partial(path);
}

Trajectory online_refine_finish(OnlineCorrector& c, const std::string& out_dir, bool write_files) {
  Trajectory final_traj = c.finish();
  const OnlineRefineStats s = c.stats();
  spdlog::info(
      "online refinement: {} keyframes, {} pair edges ({} loop candidates, {} rejected), {} solves, {} "
      "corrections applied while tracking; tracking thread {:.3f} ms a frame median ({:.3f} ms max); "
      "background {:.2f} s a keyframe median ({:.2f} s max), Ceres {:.4f} s a solve median ({:.4f} s max); "
      "{:.1f} s after the last frame for the keyframes still queued",
      s.keyframes, s.pair_edges, s.candidate_pairs, s.rejected_pairs, s.solves, s.corrections, median_of(s.handover_ms),
      max_of(s.handover_ms), median_of(s.keyframe_s), max_of(s.keyframe_s), median_of(s.solve_s), max_of(s.solve_s),
      s.final_wait_s);
  if (write_files) {
    const std::string traj = out_dir + "/trajectory.txt";
    if (std::filesystem::exists(traj)) std::filesystem::rename(traj, out_dir + "/trajectory_live.txt");
    write_tum_trajectory(out_dir + "/trajectory_odometry.txt", c.odometry());
    write_tum_trajectory(traj, final_traj);
    write_online_stats(out_dir + "/online_refine_stats.csv", s);
    spdlog::info(
        "online refinement: trajectory.txt is the final graph's trajectory, trajectory_live.txt the poses "
        "as tracked and fused (corrected while the run went), trajectory_odometry.txt the uncorrected chain");
  }
  return final_traj;
}

}  // namespace seamless
