// The reconstruction benchmark function runs every stage and reports it (not a timed test).
#include <gtest/gtest.h>

#include <map>

#include "recon/bench_recon.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

TEST(VolumeBench, ReportsEveryStageOfEveryFrame) {
  VolumeParams p = test::small_volume_params();
  p.max_depth = 4.f;  // the default: this test never limited it
  test::Scene s;
  Intrinsics K = test::camera(80, 60, 70.f);
  std::vector<ReconFrame> frames;
  for (int i = 0; i < 5; ++i) {
    SE3 T = test::pose({0.01f * i, 0.f, 0.f});
    frames.push_back({Image<float>::from_host(s.render(K, T), K.width, K.height, Device::CPU), {}, T});
  }
  ReconBenchResult r = bench_recon(frames, K, p, Device::CPU, 2);
  EXPECT_EQ(r.frames, 3);
  std::map<std::string, double> m(r.median_ms.begin(), r.median_ms.end());
  for (const char* stage : {"allocate", "visible", "fuse", "remove_empty", "raycast", "raycast_splat", "frame"}) {
    ASSERT_TRUE(m.count(stage)) << stage;
    EXPECT_GT(m[stage], 0.0) << stage;
  }
  EXPECT_LE(m["fuse"], m["frame"]);
  EXPECT_LE(m["raycast_splat"], m["raycast"]);  // a part of it
  EXPECT_EQ(r.rows.size(), 3u * 7u);
  EXPECT_GT(r.stats.allocated_blocks, 0);
}

}  // namespace
}  // namespace seamless
