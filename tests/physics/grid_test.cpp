// The neighbour grid (kernels/physics/particle_math.hpp): cell offsets of sorted keys and the
// row-wise search must visit every point within the search radius exactly once, compared with
// brute force, including scenes wider than the periodic grid and points on cell boundaries.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "core/exec.hpp"
#include "kernels/physics/particle_math.hpp"
#include "kernels/physics/solver.hpp"

namespace seamless {
namespace {

struct Mismatch {
  int missing = 0, extra = 0, repeated = 0;
};

// Sorts points into a grid of cells R / 2 wide (2^bits per axis), then compares, for every
// point, the candidates within R that for_each_in_radius yields with the brute-force set.
Mismatch compare_with_brute_force(const std::vector<vec3>& pts, float R, int bits) {
  const kernels::GridSpec g = kernels::GridSpec::for_radius(R, bits);
  const auto n = static_cast<std::int64_t>(pts.size());
  std::vector<std::uint32_t> keys(pts.size());
  std::vector<int> idx(pts.size());
  std::vector<vec3> sorted(pts.size());
  std::vector<int> start(static_cast<std::size_t>(g.cells() + 1));
  CpuExec ex;
  using Grid = kernels::NeighbourGrid<CpuExec>;
  Grid::cell_keys(ex, pts.data(), n, g, keys.data(), idx.data());
  Grid::sort_cells(ex, keys.data(), idx.data(), n, 3 * bits);
  Grid::gather_vec3(ex, pts.data(), idx.data(), n, sorted.data());
  Grid::cell_starts(ex, keys.data(), n, start.data(), g.cells());
  Mismatch m;
  std::vector<int> seen(pts.size(), -1);
  for (int s = 0; s < n; ++s) {
    const vec3 p = sorted[s];
    std::vector<int> found;
    kernels::for_each_in_radius(g, start.data(), p, R, [&](int j) {
      if (length2(p - sorted[j]) < R * R) found.push_back(j);
    });
    for (int j : found) {
      if (seen[j] == s) ++m.repeated;
      seen[j] = s;
    }
    for (int j = 0; j < n; ++j) {
      bool near = length2(p - sorted[j]) < R * R;
      if (near && seen[j] != s) ++m.missing;
      if (!near && seen[j] == s) ++m.extra;
    }
  }
  return m;
}

// Random points in a box 3x the grid's period (so far-apart points share cells), plus points on
// an exact lattice of the cell size (coordinates on cell boundaries, negative ones included).
TEST(PhysicsGrid, RowSearchFindsExactlyThePointsWithinTheRadius) {
  const float R = 0.08f;
  const int bits = 3;  // 8 cells of R / 2 per axis: period 0.32 m
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-0.5f, 0.5f);
  std::vector<vec3> pts;
  for (int i = 0; i < 1500; ++i) pts.push_back({u(rng), u(rng) * 0.3f, u(rng)});
  for (int z = -3; z <= 3; ++z)
    for (int y = -3; y <= 3; ++y)
      for (int x = -3; x <= 3; ++x) pts.push_back(vec3{float(x), float(y), float(z)} * (0.5f * R));
  Mismatch m = compare_with_brute_force(pts, R, bits);
  EXPECT_EQ(m.missing, 0);
  EXPECT_EQ(m.extra, 0);
  EXPECT_EQ(m.repeated, 0);
}

// Cell offsets: start[k] is the number of keys below k for every k in [0, cells], also for empty
// cells and long empty runs (the merge walk of kernels::NeighbourGrid::cell_starts).
TEST(PhysicsGrid, CellStartsCountKeysBelowEachCell) {
  std::vector<std::uint32_t> keys = {0, 0, 3, 40, 40, 41, 100, 511, 511};
  const std::int64_t cells = 512;
  std::vector<int> start(cells + 1, -1);
  kernels::NeighbourGrid<CpuExec>::cell_starts(CpuExec{}, keys.data(), static_cast<std::int64_t>(keys.size()),
                                               start.data(), cells);
  for (std::int64_t k = 0; k <= cells; ++k) {
    auto below = std::lower_bound(keys.begin(), keys.end(), static_cast<std::uint32_t>(k)) - keys.begin();
    ASSERT_EQ(start[k], below) << "cell " << k;
  }
}

}  // namespace
}  // namespace seamless
