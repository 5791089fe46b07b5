#include "app/bench.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>

#include "app/bench_cases.hpp"
#include "core/timing.hpp"
#include "seamless/build_config.hpp"

namespace seamless::app {

std::map<std::string, BenchInfo>& bench_registry() {
  static std::map<std::string, BenchInfo> r;
  return r;
}

void register_benchmarks() {
  bench_registry()["preprocess"] = {"bilateral filter, 3-level depth pyramid, vertex and normal maps at 640x480",
                                    make_preprocess_bench};
  bench_registry()["recon"] = {
      "TSDF allocate + fuse + raycast per 640x480 frame (hash 5 mm, dense 1 cm); --data TUM folder", make_recon_bench};
  bench_registry()["physics"] = {
      "one solver step: Table 5.1 scenes (fluid 10k, cloth 40x40, rigid 4x64) and scaled "
      "ones (fluid 1M, cloth 512x512, 4096 cubes); --scale paper|large",
      make_physics_bench};
  bench_registry()["track"] = {
      "ICP per 640x480 frame (3 levels, 10/5/4) and the whole frame (preprocess, track, "
      "fuse, raycast); --data TUM folder",
      make_tracking_bench};
#if SEAMLESS_HAS_GL
  bench_registry()["render"] = {
      "one 1920x1080 frame with 1,000,000 fluid particles (SSFR) through EGL", {}, run_render_bench};
#endif
}

}  // namespace seamless::app
