// record() -> TUM folder -> TumSource: the round trip keeps images, poses and accelerometer.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "io/input_params.hpp"
#include "io/record.hpp"
#include "io/synthetic_source.hpp"
#include "io/tum_source.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

TEST(Record, SyntheticRoomRoundTripsThroughATumFolder) {
  TmpDir dir("record");
  InputParams p;
  p.synthetic.frames = 4;
  p.synthetic.noise = true;
  p.synthetic.sensor.sigma_disparity = 0.3f;
  SyntheticSource src(p);
  ASSERT_EQ(record(src, dir.str()), 4);
  for (const char* f :
       {"rgb.txt", "depth.txt", "associations.txt", "groundtruth.txt", "accelerometer.txt", "calibration.txt"})
    EXPECT_TRUE(std::filesystem::exists(dir / f)) << f;

  InputParams q;
  q.source = InputSource::tum;
  q.path = dir.str();  // preset auto: calibration.txt gives the synthetic camera back
  TumSource back(q);
  ASSERT_EQ(back.size(), 4);
  SyntheticSource again(p);
  RgbdFrame a, b;
  for (int k = 0; k < 4; ++k) {
    ASSERT_TRUE(again.next(a));
    ASSERT_TRUE(back.next(b));
    EXPECT_NEAR(a.timestamp, b.timestamp, 1e-6);  // written with microseconds
    EXPECT_EQ(b.intrinsics.fx, a.intrinsics.fx);
    // Depth is stored in 1/5000 m units: rounding error at most 1e-4 m, plus float rounding.
    auto da = a.depth.to_host(), db = b.depth.to_host();
    for (std::size_t i = 0; i < da.size(); ++i) ASSERT_NEAR(da[i], db[i], 1e-4f + 1e-6f * da[i]) << i;
    auto ca = a.rgb.to_host(), cb = b.rgb.to_host();
    for (std::size_t i = 0; i < ca.size(); ++i)
      ASSERT_TRUE(ca[i].x == cb[i].x && ca[i].y == cb[i].y && ca[i].z == cb[i].z);
    // Poses: 7 decimals of metres, 9 of the quaternion.
    ASSERT_TRUE(b.ground_truth);
    EXPECT_LT(length(a.ground_truth->t - b.ground_truth->t), 1e-6f);
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a.ground_truth->R.m[r][c], b.ground_truth->R.m[r][c], 1e-6f);
    ASSERT_TRUE(b.accelerometer);
    EXPECT_LT(length(*a.accelerometer - *b.accelerometer), 1e-4f);  // 6 significant digits
  }
  EXPECT_FALSE(back.next(b));
}
