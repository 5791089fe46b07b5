// Online refinement (refine.online): the keyframe pose graph of the offline refinement
// (refine.hpp), grown and re-solved in a background thread while tracking runs. The tracking thread
// hands each new keyframe over a queue (a host copy of its images and its odometry pose) and, after
// each frame, picks up the newest solution if one is ready; it never waits for a solve. The
// correction of the newest solved keyframe moves the tracker's pose (TrackingSession::correct), so
// the frames after it are tracked and fused in the corrected frame. docs/TRACKING.md, "Online
// refinement".
#pragma once
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "io/frame_source.hpp"
#include "io/trajectory.hpp"
#include "recon/preprocess_params.hpp"
#include "recon/refine/refine.hpp"
#include "recon/tracker_sequence.hpp"

namespace seamless {

namespace refine_detail {
struct KeyframeData;
struct Graph;
}  // namespace refine_detail

// A solved graph as the tracking thread sees it: every keyframe in it, with the odometry pose it
// was handed over with and its refined pose (world_T_camera).
struct OnlineSolution {
  std::int64_t version = 0;          // 1 for the first solve, +1 per solve
  std::vector<std::int64_t> frames;  // keyframe frame indices, in order
  std::vector<SE3> odometry, refined;
};

struct OnlineRefineStats {
  std::int64_t keyframes = 0;  // handed over
  std::int64_t solves = 0;     // Ceres solves done in the background
  std::int64_t candidate_pairs = 0, pair_edges = 0, rejected_pairs = 0, odometry_edges = 0;
  std::int64_t corrections = 0;                         // solutions the tracking thread applied
  double max_correction_m = 0, max_correction_deg = 0;  // largest keyframe correction of the last solve
  std::vector<double> handover_ms;  // tracking thread, every frame: keyframe test, copy, queue, poll
  std::vector<double> keyframe_s;   // background, per keyframe: pyramid, pair alignments, Ceres solve
  std::vector<double> solve_s;      // ... of which the Ceres solve
  double final_wait_s = 0;          // after the last frame: until every keyframe was in a solve
};

// The background worker: a queue of keyframes in, the latest solution out. Runs on the CPU (Ceres
// is host code; the pairwise alignments use our CPU tracker with one thread, so the tracking
// thread keeps the other cores).
class OnlineRefiner {
 public:
  OnlineRefiner(const RefineParams& params, const PreprocessParams& preprocess, const Intrinsics& K);
  ~OnlineRefiner();  // stops the thread (pending keyframes are dropped)
  OnlineRefiner(const OnlineRefiner&) = delete;
  OnlineRefiner& operator=(const OnlineRefiner&) = delete;

  // Tracking thread: hands a keyframe over (frame = a host copy the worker owns). Returns at once.
  void submit(std::int64_t frame_index, double timestamp, const SE3& odometry, RgbdFrame frame);
  // Tracking thread: the newest solution, or null before the first; only a pointer copy under a lock.
  std::shared_ptr<const OnlineSolution> latest() const;
  // Waits until every submitted keyframe is in a solved graph and stops the thread.
  void finish();
  // After finish(): the poses of `odometry` (one per frame, the frames the keyframes index) moved by
  // the final graph as the offline refinement moves them (refine_steps.hpp, apply_corrections).
  Trajectory corrected(const Trajectory& odometry) const;
  // The background half of the statistics (keyframes, edges, solves, their times).
  OnlineRefineStats stats() const;
  std::string last_message() const;

 private:
  struct Item {
    std::int64_t frame;
    double timestamp;
    SE3 odometry;
    RgbdFrame images;
  };
  void run();
  void add_keyframe(Item& item);
  void solve();

  RefineParams p_;
  PreprocessParams pre_;
  Intrinsics K_;
  mutable std::mutex queue_m_;
  std::condition_variable queue_cv_, idle_cv_;
  std::deque<Item> queue_;
  bool stop_ = false, busy_ = false;
  mutable std::mutex solution_m_;
  std::shared_ptr<const OnlineSolution> latest_;
  mutable std::mutex stats_m_;
  OnlineRefineStats stats_;
  std::string message_;
  // Worker-owned (touched by the tracking thread only after finish()):
  std::vector<refine_detail::KeyframeData> kf_;
  std::unique_ptr<refine_detail::Graph> graph_;
  std::vector<SE3> refined_;
  std::thread thread_;
};

// The tracking thread's half (TrackingSession's PoseCorrector): picks keyframes among the tracked
// frames (refine.keyframes, as the offline stage), hands them over with their pose in the odometry's
// own frame (the tracker's pose with every correction applied so far taken back out, so the graph
// sees the uncorrected chain as offline), and returns the change of correction when a newer
// solution came: correction = refined * odometry^-1 of the newest solved keyframe.
class OnlineCorrector : public PoseCorrector {
 public:
  // feedback false: the tracker's pose is not corrected (frame-to-model tracking: its model was
  // fused at the uncorrected poses), only the final trajectory is.
  OnlineCorrector(const RefineParams& params, const PreprocessParams& preprocess, const Intrinsics& K, bool feedback);
  std::optional<SE3> after_frame(const RgbdFrame& frame, const FrameRecord& rec) override;

  // After the last frame: waits for the worker, returns the final trajectory (every frame moved by
  // the final graph) and fills the statistics.
  Trajectory finish();
  const Trajectory& odometry() const { return odometry_; }  // the uncorrected chain, one pose per frame
  OnlineRefineStats stats() const;
  OnlineRefiner& refiner() { return refiner_; }

 private:
  RefineParams p_;
  bool feedback_;
  OnlineRefiner refiner_;
  SE3 correction_ = SE3::identity();  // world_corrected = correction_ * odometry
  std::int64_t seen_version_ = 0, corrections_ = 0;
  std::optional<std::pair<std::int64_t, SE3>> last_keyframe_;  // index, odometry pose
  Trajectory odometry_;
  std::vector<double> handover_ms_;
  double final_wait_s_ = 0;
};

// Whether the tracker's pose may follow the corrections (not when it tracks against a fused model).
bool online_feedback(const TrackerParams& tracker);

// After an online run (out_dir empty: write nothing): trajectory.txt (as tracked, with the live
// corrections) becomes trajectory_live.txt, the uncorrected chain trajectory_odometry.txt, and
// trajectory.txt the final online graph's; online_refine_stats.csv; the summary in the log.
// Returns the final trajectory.
Trajectory online_refine_finish(OnlineCorrector& c, const std::string& out_dir, bool write_files);
void write_online_stats(const std::string& path, const OnlineRefineStats& s);

}  // namespace seamless
