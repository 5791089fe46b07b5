#include "recon/bench_recon.hpp"

#include <map>
#include <set>
#include <vector>

namespace seamless {

ReconBench::ReconBench(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params, Device d)
    : K_(K), device_(d), volume_(make_volume(params, d)), timer_(std::make_unique<StageTimer>(d)) {
  for (const ReconFrame& f : frames)
    frames_.push_back({f.depth.clone(d), f.rgb.width() ? f.rgb.clone(d) : Image<uchar3>{}, f.world_T_camera});
}

void ReconBench::step() {
  const ReconFrame& f = frames_[static_cast<std::size_t>(next_ % static_cast<std::int64_t>(frames_.size()))];
  timer_->begin("frame");
  volume_->integrate(f.depth, f.rgb, K_, f.world_T_camera, timer_.get());
  volume_->raycast(K_, f.world_T_camera, maps_, timer_.get());
  timer_->end("frame");
  timer_->end_frame(next_++);
  ++timed_;
}

void ReconBench::reset_timing() {
  timer_ = std::make_unique<StageTimer>(device_);
  timed_ = 0;
}

ReconBenchResult ReconBench::result() {
  ReconBenchResult r;
  r.frames = static_cast<int>(timed_);
  r.rows = timer_->rows();
  std::vector<std::string> stages;
  std::set<std::string> seen;
  for (const auto& row : r.rows)
    if (seen.insert(row.stage).second) stages.push_back(row.stage);
  for (const std::string& s : stages) r.median_ms.emplace_back(s, timer_->median_ms(s));
  r.stats = volume_->stats();
  return r;
}

// Median over the timed frames of the frame's allocate + visible + fuse + raycast GPU time (the
// issue's goal): the median of the per-frame sums, not the sum of the stage medians, which may
// come from different frames.
double ReconBench::goal_stages_median_ms() const {
  std::map<std::int64_t, double> sum;
  for (const StageTimer::Row& row : timer_->rows())
    if (row.stage == "allocate" || row.stage == "visible" || row.stage == "fuse" || row.stage == "raycast")
      sum[row.frame] += row.ms;
  std::vector<double> v;
  for (const auto& [frame, ms] : sum) v.push_back(ms);
  return median(v);  // core/timing.hpp: the convention of the stage medians
}

std::string ReconBench::report() {
  VolumeStats s = volume_->stats();
  std::string r = "stage medians (ms):";
  for (const char* st : {"allocate", "visible", "fuse", "remove_empty", "raycast_splat", "raycast_window", "raycast"})
    if (double m = timer_->median_ms(st); m > 0) r += std::string(" ") + st + " " + std::to_string(m);
  r += "; allocate+visible+fuse+raycast per frame (median) " + std::to_string(goal_stages_median_ms());
  return r + "; blocks " + std::to_string(s.allocated_blocks) + ", " + std::to_string(s.bytes_per_block) +
         " bytes/block";
}

ReconBenchResult bench_recon(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params,
                             Device d, int warmup) {
  ReconBench b(frames, K, params, d);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (static_cast<int>(i) == warmup) b.reset_timing();
    b.step();
  }
  if (static_cast<int>(frames.size()) <= warmup) b.reset_timing();  // all warm-up: nothing reported
  return b.result();
}

}  // namespace seamless
