#include "recon/bench_recon.hpp"

#include <set>

namespace seamless {

ReconBenchResult bench_recon(const std::vector<ReconFrame>& frames, const Intrinsics& K, const VolumeParams& params,
                             Device d, int warmup) {
  std::vector<ReconFrame> dev;
  for (const ReconFrame& f : frames)
    dev.push_back({f.depth.clone(d), f.rgb.width() ? f.rgb.clone(d) : Image<uchar3>{}, f.world_T_camera});
  auto volume = make_volume(params, d);
  RaycastMaps maps;
  StageTimer warm(d), timer(d);
  std::int64_t index = 0;
  for (const ReconFrame& f : dev) {
    StageTimer& t = index < warmup ? warm : timer;
    t.begin("frame");
    volume->integrate(f.depth, f.rgb, K, f.world_T_camera, &t);
    volume->raycast(K, f.world_T_camera, maps, &t);
    t.end("frame");
    t.end_frame(index++);
  }
  ReconBenchResult r;
  r.frames = static_cast<int>(std::max<std::int64_t>(0, index - warmup));
  r.rows = timer.rows();
  std::vector<std::string> stages;
  std::set<std::string> seen;
  for (const auto& row : r.rows)
    if (seen.insert(row.stage).second) stages.push_back(row.stage);
  for (const std::string& s : stages) r.median_ms.emplace_back(s, timer.median_ms(s));
  r.stats = volume->stats();
  return r;
}

}  // namespace seamless
