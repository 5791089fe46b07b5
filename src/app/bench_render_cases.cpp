// `seamless bench render`: src/render/bench_render times its passes with GL timer queries.
#include <cstdio>
#include <fstream>

#include "app/bench_cases.hpp"
#include "render/bench_render.hpp"

namespace seamless::app {

namespace {
RenderBenchResult run_one(const char* label, const RenderParams& settings, int reps) {
  RenderBenchResult r = bench_render(1920, 1080, 1'000'000, reps, settings);
  std::printf("render %s: %dx%d, %lld particles, %d frames on %s\n", label, r.width, r.height,
              static_cast<long long>(r.particles), r.frames, r.gl_renderer.c_str());
  std::printf("  median frame (upload + draw) %.3f ms, draw only %.3f ms, readback %.3f ms", r.median_frame_ms,
              r.median_draw_ms, r.median_readback_ms);
  if (r.median_interop_ms >= 0) std::printf(", CUDA interop copy + draw %.3f ms", r.median_interop_ms);
  std::printf("\n");
  for (const RenderTiming& t : r.passes) std::printf("  pass %-20s %.3f ms\n", t.pass.c_str(), t.ms);
  return r;
}
}  // namespace

// The default settings (render.thickness_downsample, depth_prepass, narrow-range filter, ...) and,
// for comparison, the same scene with every speed remedy off.
int run_render_bench(const BenchOptions& o, int reps, const std::string& json) {
  RenderBenchResult r = run_one("default settings", RenderParams{}, reps);
  if (o.scale != "paper") run_one("without the speed remedies", unoptimised_render_settings(), reps);
  if (!json.empty()) {
    std::ofstream f(json);
    f << "{\"benchmark\": \"render\", \"gl\": \"" << r.gl_renderer << "\", \"median_frame_ms\": " << r.median_frame_ms
      << ", \"median_draw_ms\": " << r.median_draw_ms << ", \"median_readback_ms\": " << r.median_readback_ms
      << ", \"median_interop_ms\": " << r.median_interop_ms << "}\n";
  }
  return 0;
}

}  // namespace seamless::app
