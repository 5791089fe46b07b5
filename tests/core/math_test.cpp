// seamless::floor_int against std::floor, and its behaviour where a conversion to int would be
// undefined (a projection divided by a depth near zero, a NaN): a far index, no UB (the sanitizer
// step runs this file under UBSan). orthonormal_basis (core/basis.hpp) against the definition of a right-handed
// orthonormal basis. eigen_sym3 (core/sym3.hpp) against matrices built from known eigenvalues.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "core/basis.hpp"
#include "core/math.hpp"
#include "core/sym3.hpp"

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

// eigen_sym3 on A = Q diag(l) Q^T (Q a random rotation, in double) rounded to float: V diag(e) V^T
// gives back the float A, V is orthonormal, and the sorted e are l. Rounding A to float moves its
// eigenvalues by at most the rounding's norm (Weyl), which the eigenvalue check adds. The rest is
// the solver's own rounding, a few dozen float operations on entries of the size of |A|: 7e-7 of
// |A| at worst over two million such matrices, hence 1.5e-6 (one Newton step fewer gives 2.3e-6).
// The kinds include what Jacobi-free solvers get wrong: repeated eigenvalues (a disc's two equal
// axes, c I inside a body of fluid), nearly repeated ones, and rank-deficient matrices.
TEST(EigenSym3, ReproducesMatricesOfKnownEigenvalues) {
  constexpr double kTol = 1.5e-6;
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto check = [&](const std::array<double, 9>& A, std::array<double, 3> l, const char* kind) {
    const sym3 S{float(A[0]), float(A[1]), float(A[2]), float(A[4]), float(A[5]), float(A[8])};
    const std::array<double, 9> Af{S.xx, S.xy, S.xz, S.xy, S.yy, S.yz, S.xz, S.yz, S.zz};
    mat3 V;
    vec3 e;
    eigen_sym3(S, V, e);
    double norm = 0.0, rounding = 0.0, rec = 0.0, orth = 0.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        const double r = V.m[i][0] * double(e.x) * V.m[j][0] + V.m[i][1] * double(e.y) * V.m[j][1] +
                         V.m[i][2] * double(e.z) * V.m[j][2];
        const double g = double(V.m[0][i]) * V.m[0][j] + double(V.m[1][i]) * V.m[1][j] + double(V.m[2][i]) * V.m[2][j];
        norm += A[3 * i + j] * A[3 * i + j];
        rounding += (Af[3 * i + j] - A[3 * i + j]) * (Af[3 * i + j] - A[3 * i + j]);
        rec += (r - Af[3 * i + j]) * (r - Af[3 * i + j]);
        orth += (g - (i == j)) * (g - (i == j));
      }
    norm = std::sqrt(norm), rounding = std::sqrt(rounding);
    EXPECT_LE(std::sqrt(rec), kTol * norm) << kind;
    EXPECT_LE(std::sqrt(orth), kTol) << kind;
    std::array<double, 3> got{e.x, e.y, e.z};
    std::sort(got.begin(), got.end());
    std::sort(l.begin(), l.end());
    for (int i = 0; i < 3; ++i)
      EXPECT_LE(std::abs(got[i] - l[i]), rounding + kTol * norm) << kind << " eigenvalue " << i;
  };
  auto rotated = [&](std::array<double, 3> l, const char* kind) {
    double q[4] = {u(rng), u(rng), u(rng), u(rng)};
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& c : q) c /= n;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    const double Q[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    std::array<double, 9> A{};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        for (int k = 0; k < 3; ++k) A[3 * i + j] += Q[i][k] * l[k] * Q[j][k];
    check(A, l, kind);
  };
  for (int k = 0; k < 3000; ++k) {
    const double a = u(rng), b = u(rng), c = u(rng);
    rotated({a, b, c}, "distinct");
    rotated({a, a, b}, "a double eigenvalue");
    rotated({a, a * (1 + 1e-4 * b), c}, "a nearly double eigenvalue");
    rotated({c, c, c}, "c I");
    rotated({a, b, 0.0}, "rank 2");
    rotated({a, 0.0, 0.0}, "rank 1");
    // A covariance of a nearly isotropic neighbourhood: positive, of the scale of (1 cm)^2.
    const double s = 1e-4 * std::abs(a);
    rotated({s, s * (1 + 1e-6 * b), s * (1 + 1e-5 * c)}, "nearly isotropic");
  }
  // Exact ones: zero, c I, diagonal with a repeated entry, and all ones (rank 1, eigenvalue 3).
  check({0, 0, 0, 0, 0, 0, 0, 0, 0}, {0, 0, 0}, "zero");
  check({2, 0, 0, 0, 2, 0, 0, 0, 2}, {2, 2, 2}, "2 I");
  check({2, 0, 0, 0, 2, 0, 0, 0, 5}, {2, 2, 5}, "diag(2, 2, 5)");
  check({1, 1, 1, 1, 1, 1, 1, 1, 1}, {0, 0, 3}, "ones");
}

}  // namespace
}  // namespace seamless
