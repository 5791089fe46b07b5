// seamless::floor_int against std::floor, and its behaviour where a conversion to int would be
// undefined (a projection divided by a depth near zero, a NaN): a far index, no UB (the sanitizer
// step runs this file under UBSan). orthonormal_basis (core/basis.hpp) against the definition of a right-handed
// orthonormal basis.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/basis.hpp"
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

// For unit n in every direction (a sphere of directions, the axes, and directions near the x axis
// where the helper axis switches), t1, t2 are unit, orthogonal to each other and to n, and
// t1 x t2 = n. Float rounding of a few products: 1e-5 is about 100 ulps of 1.
TEST(OrthonormalBasis, IsRightHandedAndOrthonormalForEveryDirection) {
  std::vector<vec3> dirs = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  for (float x : {0.89f, 0.9f, 0.91f, -0.9f}) dirs.push_back({x, std::sqrt(1.f - x * x), 0.f});
  for (int i = 0; i < 16; ++i)
    for (int j = 0; j < 32; ++j) {
      const float th = 3.14159265f * (i + 0.5f) / 16, ph = 2 * 3.14159265f * j / 32;
      dirs.push_back({std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)});
    }
  for (const vec3 n : dirs) {
    vec3 t1, t2;
    orthonormal_basis(n, t1, t2);
    EXPECT_NEAR(length(t1), 1.f, 1e-5f);
    EXPECT_NEAR(length(t2), 1.f, 1e-5f);
    EXPECT_NEAR(dot(t1, t2), 0.f, 1e-5f);
    EXPECT_NEAR(dot(t1, n), 0.f, 1e-5f);
    EXPECT_NEAR(dot(t2, n), 0.f, 1e-5f);
    EXPECT_NEAR(length(cross(t1, t2) - n), 0.f, 1e-5f) << n.x << " " << n.y << " " << n.z;
  }
  // Up along +y (the usual gravity): exact axes, t1 = -z, t2 = -x.
  vec3 t1, t2;
  orthonormal_basis({0.f, 1.f, 0.f}, t1, t2);
  EXPECT_EQ(t1.x, 0.f);
  EXPECT_EQ(t1.y, 0.f);
  EXPECT_EQ(t1.z, -1.f);
  EXPECT_EQ(t2.x, -1.f);
  EXPECT_EQ(t2.y, 0.f);
  EXPECT_EQ(t2.z, 0.f);
}

}  // namespace
}  // namespace seamless
