// `seamless bench track`: ICP per frame (3 levels, 10/5/4) and the whole tracked frame
// (src/recon/bench_track builds them); --data TUM folder for real frames.
#include "app/bench_cases.hpp"
#include "recon/bench_track.hpp"

namespace seamless::app {

std::vector<BenchCase> make_tracking_bench(const BenchOptions& o) {
  std::vector<BenchCase> cases;
  for (TrackBenchCase& c : make_track_bench(o.device, o.data_dir)) cases.push_back({c.name, c.step, c.detail});
  return cases;
}

}  // namespace seamless::app
