// seamless::floor_int against std::floor, and its behaviour where a conversion to int would be
// undefined (a projection divided by a depth near zero, a NaN): a far index, no UB (the sanitizer
// step runs this file under UBSan).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "core/math.hpp"

namespace seamless {
namespace {

TEST(FloorInt, EqualsStdFloorWhereTheFloorFitsAnInt) {
  for (const float x :
       {0.f,       -0.f,       0.5f,       -0.5f,       1.f,        -1.f,        1.999f, -1.001f, 7.f,  -7.f,
        123456.7f, -123456.7f, 16777215.f, -16777215.f, 33554430.f, -33554430.f, 1e-30f, -1e-30f, 1e9f, -1e9f}) {
    EXPECT_EQ(floor_int(x), static_cast<int>(std::floor(x))) << x;
  }
}

TEST(FloorInt, HoldsHugeInfiniteAndNanValuesAtAFarIndex) {
  const float inf = std::numeric_limits<float>::infinity();
  const int far = static_cast<int>(kFloorIntRange);
  EXPECT_EQ(floor_int(3e9f), far);
  EXPECT_EQ(floor_int(inf), far);
  EXPECT_EQ(floor_int(-3e9f), -far);
  EXPECT_EQ(floor_int(-inf), -far);
  EXPECT_EQ(floor_int(std::numeric_limits<float>::quiet_NaN()), -far);
}

}  // namespace
}  // namespace seamless
