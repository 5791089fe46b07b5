// The rate and time left the progress display shows (core/progress.hpp), against hand-computed values.
#include <gtest/gtest.h>

#include "core/progress.hpp"

using seamless::progress_rate_text;

TEST(Progress, RateAndTimeLeftAtThatRate) {
  // 40 of 100 frames in 3.2 s: 12.5 fps; 60 left at 12.5 fps = 4.8 s.
  EXPECT_EQ(progress_rate_text(40, 100, 3.2), "12.5 fps, 4.8 s left");
  // 3 of 300 in 2 s: 1.5 fps, 297 / 1.5 = 198 s = 3:18.
  EXPECT_EQ(progress_rate_text(3, 300, 2.0), "1.50 fps, 3:18 left");
  // 10 of 40000 steps in 1 s: 39990 steps at 10 steps/s = 3999 s = 1:06:39.
  EXPECT_EQ(progress_rate_text(10, 40000, 1.0, "steps/s"), "10.0 steps/s, 1:06:39 left");
  // 45 s left prints whole seconds; done means nothing left.
  EXPECT_EQ(progress_rate_text(50, 95, 50.0), "1.00 fps, 45 s left");
  EXPECT_EQ(progress_rate_text(100, 100, 8.0), "12.5 fps, 0.0 s left");
}

TEST(Progress, NothingToSayBeforeTheFirstItemOrWithoutATotal) {
  EXPECT_EQ(progress_rate_text(0, 100, 1.0), "");
  EXPECT_EQ(progress_rate_text(5, 100, 0.0), "");
  EXPECT_EQ(progress_rate_text(30, 0, 2.0), "15.0 fps");  // a live source of unknown length
}
