// `seamless bench render`: src/render/bench_render times its passes with GL timer queries.
#include <cstdio>
#include <fstream>

#include "app/bench_cases.hpp"
#include "render/bench_render.hpp"

namespace seamless::app {

int run_render_bench(const BenchOptions&, int reps, const std::string& json) {
  RenderBenchResult r = bench_render(1920, 1080, 1'000'000, reps);
  std::printf("render %dx%d, %lld particles, %d frames on %s\n", r.width, r.height,
              static_cast<long long>(r.particles), r.frames, r.gl_renderer.c_str());
  std::printf("  median frame (upload + draw) %.3f ms, draw only %.3f ms, readback %.3f ms\n", r.median_frame_ms,
              r.median_draw_ms, r.median_readback_ms);
  for (const RenderTiming& t : r.passes) std::printf("  pass %-20s %.3f ms\n", t.pass.c_str(), t.ms);
  if (!json.empty()) {
    std::ofstream f(json);
    f << "{\"benchmark\": \"render\", \"gl\": \"" << r.gl_renderer << "\", \"median_frame_ms\": " << r.median_frame_ms
      << ", \"median_draw_ms\": " << r.median_draw_ms << ", \"median_readback_ms\": " << r.median_readback_ms << "}\n";
  }
  return 0;
}

}  // namespace seamless::app
