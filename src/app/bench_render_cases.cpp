// `seamless bench render`: src/render/bench_render times its passes with GL timer queries.
#include <cstdio>

#include "app/bench_cases.hpp"
#include "app/json_file.hpp"
#include "render/bench_render.hpp"
#include "seamless/build_config.hpp"

namespace seamless::app {

namespace {
RenderBenchResult run_one(const char* label, const RenderParams& settings, int reps) {
  RenderBenchResult r = bench_render(1920, 1080, 1'000'000, reps, settings);
  std::printf("render %s (fluid_splat %s): %dx%d, %lld particles, %d frames on %s\n", label,
              enum_name(settings.fluid_splat), r.width, r.height, static_cast<long long>(r.particles), r.frames,
              r.gl_renderer.c_str());
  std::printf("  median GPU time per frame %.3f ms (sum of the passes below, timer queries)\n", r.median_gpu_ms);
  std::printf("  median wall time: draw only %.3f ms, upload + draw %.3f ms, readback %.3f ms", r.median_draw_ms,
              r.median_frame_ms, r.median_readback_ms);
  if (r.median_interop_ms >= 0) std::printf(", CUDA interop copy + draw %.3f ms", r.median_interop_ms);
  std::printf("\n");
  if (r.median_ellipsoid_ms >= 0)
    std::printf("  anisotropic kernels (%s, before the GL passes, in the interop figure) %.3f ms\n",
                r.ellipsoid_device.c_str(), r.median_ellipsoid_ms);
  for (const RenderTiming& t : r.passes) std::printf("  pass %-20s %.3f ms\n", t.pass.c_str(), t.ms);
  return r;
}

void write_json(const std::string& path, const RenderBenchResult& r) {
  Json passes = Json::object();
  for (const RenderTiming& t : r.passes) passes[t.pass] = t.ms;
  write_json_file(path, {{"benchmark", "render"},
                         {"seamless_version", SEAMLESS_VERSION},
                         {"gl", r.gl_renderer},
                         {"median_gpu_ms", r.median_gpu_ms},
                         {"median_frame_ms", r.median_frame_ms},
                         {"median_draw_ms", r.median_draw_ms},
                         {"median_readback_ms", r.median_readback_ms},
                         {"median_interop_ms", r.median_interop_ms},
                         {"median_ellipsoid_ms", r.median_ellipsoid_ms},
                         {"passes_ms", std::move(passes)}});
}
}  // namespace

// The default settings (compute splats, thickness_downsample, narrow-range filter, shadows, ...)
// and, for comparison, the same without shadows, with raster sprites, and with every speed remedy off.
int run_render_bench(const BenchOptions& o, int reps, const std::string& json) {
  RenderBenchResult r = run_one("default settings", RenderParams{}, reps);
  if (o.scale != "paper") {
    RenderParams no_shadows;  // what the shadow pass and the shadow lookups cost
    no_shadows.shadows = false;
    run_one("default settings without shadows", no_shadows, reps);
    RenderParams raster;
    raster.fluid_splat = FluidSplat::raster;
    run_one("default settings but raster sprites", raster, reps);
    run_one("without the speed remedies", unoptimised_render_settings(), reps);
  }
  if (!json.empty()) write_json(json, r);
  return 0;
}

}  // namespace seamless::app
