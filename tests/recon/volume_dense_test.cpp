// The dense grid behind the same interface: same fusion, raycast and mesh as the hashed volume.
#include <gtest/gtest.h>

#include <cmath>

#include "recon/volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

TEST(VolumeDense, MatchesTheHashedVolume) {
  VolumeParams p = test::small_volume_params();
  p.max_depth = 4.f;                        // the default: this test never limited it
  p.dense_resolution = 128;                 // 1.28 m cube
  p.dense_origin = {-0.64f, -0.64f, 0.8f};  // holds the sphere and the wall's centre
  test::Scene s;
  Intrinsics K = test::camera(160, 120, 140.f);
  p.layout = VolumeLayout::hash;
  auto hash = make_volume(p, Device::CPU);
  p.layout = VolumeLayout::dense;
  auto dense = make_volume(p, Device::CPU);
  for (SE3 T : {test::pose({0.f, 0.f, 0.f}), test::pose({0.03f, 0.02f, 0.f})}) {
    auto depth = Image<float>::from_host(s.render(K, T), K.width, K.height, Device::CPU);
    hash->integrate(depth, {}, K, T);
    dense->integrate(depth, {}, K, T);
  }
  // On the wall both volumes fuse the same voxels with the same (exact, fronto-parallel) values:
  // the dense origin is on the voxel lattice, so the raycasts agree to float rounding. (On the
  // sphere they may differ by up to the fusion error: a hash block allocated only by the second
  // frame never saw the first, while the dense grid fused both.)
  auto truth = s.render(K, SE3::identity());
  auto dh = hash->raycast(K, SE3::identity()).depth.to_host();
  auto dd = dense->raycast(K, SE3::identity()).depth.to_host();
  int both = 0;
  for (int y = 30; y < 90; ++y)
    for (int x = 40; x < 120; ++x) {
      std::size_t i = static_cast<std::size_t>(y) * K.width + x;
      if (dh[i] > 0.f && dd[i] > 0.f && std::fabs(truth[i] - s.wall_z) < 1e-6f) {
        ++both;
        EXPECT_NEAR(dh[i], dd[i], 1e-4f);
      }
    }
  EXPECT_GT(both, 2000);
  EXPECT_EQ(dense->stats().allocated_blocks, 16 * 16 * 16);
  Mesh m = dense->extract_mesh();
  ASSERT_GT(m.triangles.size(), 1000u);
  for (vec3 v : m.positions) EXPECT_LE(std::fabs(s.sdf(v)), 0.03f);  // within the truncation
}

}  // namespace
}  // namespace seamless
