// recon/mask_score: the dynamic mask against the movers' ground truth (the mask test of docs/DYNAMIC.md), on
// hand-made masks whose counts are known.
#include "recon/mask_score.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.hpp"

namespace seamless {
namespace {

// Mover `id` as a sphere of radius 0.1 on the z axis whose surface is `distance` metres from the
// origin (the camera).
void add_sphere(kernels::movers::Scene& s, float distance, int id) {
  kernels::movers::Capsule& c = s.c[s.count++];
  c.a = c.b = {0.f, 0.f, distance + 0.1f};
  c.r = 0.1f;
  c.mover = id;
}
kernels::movers::Scene two_movers(float person, float ball) {
  kernels::movers::Scene s;
  add_sphere(s, person, 1);
  add_sphere(s, ball, 2);
  return s;
}
const vec3 kEye{0.f, 0.f, 0.f};
const std::vector<int> kPeople{1};  // mover 1 is the person, mover 2 a ball

// 4 x 4 pixels: mover 1 on 4, mover 2 on 2; the mask on 3 of mover 1's and on 1 static pixel.
std::vector<std::uint8_t> truth_4x4() { return {1, 1, 0, 0, 1, 1, 0, 0, 0, 0, 2, 2, 0, 0, 0, 0}; }
std::vector<std::uint8_t> mask_4x4() { return {1, 1, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1}; }

TEST(MaskScore, CountsPixelsPerMover) {
  const MaskScore s = score_mask(truth_4x4(), mask_4x4(), two_movers(1.f, 2.f), kEye);
  EXPECT_EQ(s.pixels, 16);
  EXPECT_EQ(s.truth, 6);
  EXPECT_EQ(s.masked, 4);
  EXPECT_EQ(s.both, 3);
  EXPECT_DOUBLE_EQ(s.iou(), 3.0 / 7.0);  // 3 in both of the 6 + 4 - 3 in either
  ASSERT_EQ(s.mover_truth.size(), 2u);
  EXPECT_EQ(s.mover_truth[0], 4);
  EXPECT_EQ(s.mover_masked[0], 3);
  EXPECT_EQ(s.mover_truth[1], 2);
  EXPECT_EQ(s.mover_masked[1], 0);
  ASSERT_EQ(s.mover_distance.size(), 2u);
  EXPECT_NEAR(s.mover_distance[0], 1.f, 1e-6f);
  EXPECT_NEAR(s.mover_distance[1], 2.f, 1e-6f);
  EXPECT_THROW(score_mask(truth_4x4(), std::vector<std::uint8_t>(15, 0), two_movers(1.f, 2.f), kEye), Error);
}

TEST(MaskScore, ScoresFramesWithEveryPersonHalfAMetreAwayAndTheMoversInView) {
  const auto truth = truth_4x4(), mask = mask_4x4();
  EXPECT_TRUE(mask_scored(score_mask(truth, mask, two_movers(0.51f, 2.f), kEye), kPeople));
  EXPECT_FALSE(mask_scored(score_mask(truth, mask, two_movers(0.49f, 2.f), kEye), kPeople));  // person too near
  EXPECT_TRUE(mask_scored(score_mask(truth, mask, two_movers(1.f, 0.3f), kEye), kPeople));    // a near ball: fine
  EXPECT_FALSE(mask_scored(score_mask(truth, mask, two_movers(1.f, 0.3f), kEye), {}));        // every mover a person
  kernels::movers::Scene ball_only;
  add_sphere(ball_only, 2.f, 2);
  EXPECT_FALSE(mask_scored(score_mask(truth, mask, ball_only, kEye), kPeople));  // no person in the room
  EXPECT_TRUE(mask_scored(score_mask(truth, mask, ball_only, kEye), {}));
  // Movers on 1 pixel of 128 (under 1 % of the image) are not scored; on 2 of 128 they are.
  std::vector<std::uint8_t> big_truth(128, 0), big_mask(128, 0);
  big_truth[5] = 1;
  EXPECT_FALSE(mask_scored(score_mask(big_truth, big_mask, two_movers(1.f, 2.f), kEye), kPeople));
  big_truth[6] = 1;
  EXPECT_TRUE(mask_scored(score_mask(big_truth, big_mask, two_movers(1.f, 2.f), kEye), kPeople));
}

TEST(MaskScore, RunQualityOverFrames) {
  EXPECT_FALSE(mask_quality({}, kPeople).has_value());
  const MaskScore good = score_mask(truth_4x4(), truth_4x4(), two_movers(1.f, 2.f), kEye);  // IoU 1
  const MaskScore part = score_mask(truth_4x4(), mask_4x4(), two_movers(1.f, 2.f), kEye);   // IoU 3/7
  const MaskScore near = score_mask(truth_4x4(), mask_4x4(), two_movers(0.3f, 2.f), kEye);  // not scored
  const auto q = mask_quality({{1, good}, {2, part}, {3, near}}, kPeople);
  ASSERT_TRUE(q.has_value());
  EXPECT_EQ(q->frames, 2);
  EXPECT_DOUBLE_EQ(q->min_iou, 3.0 / 7.0);
  EXPECT_DOUBLE_EQ(q->mean_iou, (1.0 + 3.0 / 7.0) / 2.0);
  ASSERT_EQ(q->below.size(), 1u);
  EXPECT_EQ(q->below[0].first, 2);
  // Recall and precision count every frame with a score, the near one too: mover 1 found on
  // 4 + 3 + 3 of its 12 pixels, mover 2 on 2 of 6; 6 + 3 + 3 of the 6 + 4 + 4 masked pixels.
  ASSERT_EQ(q->mover_recall.size(), 2u);
  EXPECT_DOUBLE_EQ(q->mover_recall[0], 10.0 / 12.0);
  EXPECT_DOUBLE_EQ(q->mover_recall[1], 2.0 / 6.0);
  EXPECT_DOUBLE_EQ(q->precision, 12.0 / 14.0);
  // No frame scored: no IoU statistics, recall and precision still counted.
  const auto qn = mask_quality({{3, near}}, kPeople);
  EXPECT_EQ(qn->frames, 0);
  EXPECT_TRUE(std::isnan(qn->min_iou));
  EXPECT_TRUE(std::isnan(qn->mean_iou));
  EXPECT_DOUBLE_EQ(qn->mover_recall[0], 3.0 / 4.0);
  EXPECT_DOUBLE_EQ(qn->precision, 3.0 / 4.0);
  // A mover in the room but never in view has no recall.
  std::vector<std::uint8_t> only_ball = truth_4x4();
  for (auto& v : only_ball) v = v == 2 ? 2 : 0;
  const auto qb = mask_quality({{1, score_mask(only_ball, mask_4x4(), two_movers(1.f, 2.f), kEye)}}, kPeople);
  ASSERT_EQ(qb->mover_recall.size(), 2u);
  EXPECT_TRUE(std::isnan(qb->mover_recall[0]));
  EXPECT_DOUBLE_EQ(qb->mover_recall[1], 0.0);
}

}  // namespace
}  // namespace seamless
