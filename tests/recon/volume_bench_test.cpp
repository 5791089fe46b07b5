// The reconstruction benchmark runs every stage and reports it (not a timed test): bench_recon()
// and the ReconBench steps that `seamless bench recon` registers are one code path.
#include <gtest/gtest.h>

#include <map>
#include <string>

#include "recon/bench_recon.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

VolumeParams bench_params() {
  VolumeParams p = test::small_volume_params();
  p.max_depth = 4.f;  // the default: this test never limited it
  return p;
}

const Intrinsics kK = test::camera(80, 60, 70.f);

std::vector<ReconFrame> bench_frames(int n) {
  test::Scene s;
  std::vector<ReconFrame> frames;
  for (int i = 0; i < n; ++i) {
    SE3 T = test::pose({0.01f * i, 0.f, 0.f});
    frames.push_back({Image<float>::from_host(s.render(kK, T), kK.width, kK.height, Device::CPU), {}, T});
  }
  return frames;
}

TEST(VolumeBench, ReportsEveryStageOfEveryFrame) {
  ReconBenchResult r = bench_recon(bench_frames(5), kK, bench_params(), Device::CPU, 2);
  EXPECT_EQ(r.frames, 3);
  std::map<std::string, double> m(r.median_ms.begin(), r.median_ms.end());
  for (const char* stage : {"allocate", "visible", "fuse", "remove_empty", "raycast", "raycast_splat", "frame"}) {
    ASSERT_TRUE(m.count(stage)) << stage;
    EXPECT_GT(m[stage], 0.0) << stage;
  }
  EXPECT_LE(m["fuse"], m["frame"]);
  EXPECT_LE(m["raycast_splat"], m["raycast"]);  // a part of it
  EXPECT_FALSE(m.count("raycast_window"));      // with ray intervals the splat fills the window
  EXPECT_EQ(r.rows.size(), 3u * 7u);
  EXPECT_GT(r.stats.allocated_blocks, 0);
}

// What `seamless bench recon` calls: one frame per step, cycling through the frames; its report
// names the stage medians and the volume's blocks; a reset forgets the timing, not the volume.
TEST(VolumeBench, StepsCycleAndReportStagesAndBlocks) {
  ReconBench b(bench_frames(3), kK, bench_params(), Device::CPU);
  for (int i = 0; i < 7; ++i) b.step();
  ReconBenchResult r = b.result();
  EXPECT_EQ(r.frames, 7);
  // allocate, visible, fuse, remove_empty, raycast_splat (which fills the window), raycast, frame
  EXPECT_EQ(r.rows.size(), 7u * 7u);
  // The goal's figure: every frame's allocate + visible + fuse + raycast lies within the frame and
  // includes its raycast, so the median of those sums lies between the two medians.
  std::map<std::string, double> m(r.median_ms.begin(), r.median_ms.end());
  EXPECT_GE(b.goal_stages_median_ms(), m["raycast"]);
  EXPECT_LE(b.goal_stages_median_ms(), m["frame"]);
  const std::string rep = b.report();
  EXPECT_EQ(rep.rfind("stage medians (ms): allocate ", 0), 0u) << rep;
  for (const char* stage : {" visible ", " fuse ", " remove_empty ", " raycast_splat ", " raycast ",
                            " allocate+visible+fuse+raycast per frame (median) "})
    EXPECT_NE(rep.find(stage), std::string::npos) << stage << " in " << rep;
  EXPECT_NE(rep.find("; blocks " + std::to_string(r.stats.allocated_blocks) + ", "), std::string::npos) << rep;
  b.reset_timing();
  ReconBenchResult after = b.result();
  EXPECT_EQ(after.frames, 0);
  EXPECT_TRUE(after.rows.empty());
  EXPECT_EQ(after.stats.allocated_blocks, r.stats.allocated_blocks);
}

TEST(VolumeBench, AllWarmUpReportsNoFrame) {
  ReconBenchResult r = bench_recon(bench_frames(2), kK, bench_params(), Device::CPU, 2);
  EXPECT_EQ(r.frames, 0);
  EXPECT_TRUE(r.rows.empty());
}

}  // namespace
}  // namespace seamless
