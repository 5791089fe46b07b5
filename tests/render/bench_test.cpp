// The render benchmark runs (small here; 1920x1080 with 10^6 particles is for the GPU machine).
#include "render/bench_render.hpp"
#include "render_test_util.hpp"

namespace seamless::test {
namespace {

TEST(RenderBench, SmallRunReportsEveryPass) {
  SEAMLESS_REQUIRE_EGL();
  const RenderBenchResult r = bench_render(96, 64, 1000, 2);
  EXPECT_EQ(r.particles, 1000);
  EXPECT_EQ(r.frames, 2);
  EXPECT_GT(r.median_frame_ms, 0.0);
  EXPECT_GT(r.median_draw_ms, 0.0);
  // The GPU frame time is the sum of the passes' timestamp differences, all of them >= 0.
  double sum = 0.0;
  for (const RenderTiming& t : r.passes) {
    EXPECT_GE(t.ms, 0.0) << t.pass;
    sum += t.ms;
  }
  EXPECT_GT(r.median_gpu_ms, 0.0);
  // With 2 frames every median is the larger of two values, and the larger of two sums is at most
  // the sum of the larger parts.
  EXPECT_LE(r.median_gpu_ms, sum * (1 + 1e-12));
  std::vector<std::string> names;
  for (const RenderTiming& t : r.passes) names.push_back(t.pass);
  const std::vector<std::string> want = {"shadow",       "scene",           "objects",       "fluid_depth",
                                         "fluid_filter", "fluid_thickness", "fluid_normals", "fluid_composite"};
  EXPECT_EQ(names, want);
}

}  // namespace
}  // namespace seamless::test
