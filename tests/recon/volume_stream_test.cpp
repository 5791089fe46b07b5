// Streaming of voxel blocks to host memory and back (Niessner et al. 2013, section 5): a block is
// on exactly one side, a round trip changes no voxel and no triangle, and fusing along a path with
// streaming gives the same volume as fusing without.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <tuple>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "recon/voxel_hash_volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

// 80x60 pixels, f = 70: the image corner ray is 1.229 times its depth long, so a frame touches
// blocks up to (3 + 0.03) * 1.229 + 0.14 (block diagonal) = 3.86 m away; with 0.25 m between
// passes the radius must be at least 4.11 m.
Intrinsics small_camera() { return test::camera(80, 60, 70.f); }

VolumeParams params(float stream_radius) {
  VolumeParams p = test::small_volume_params();
  p.stream_radius = stream_radius;
  p.stream_step = 0.25f;
  return p;
}

void fuse(Volume& vol, const test::Scene& s, const Intrinsics& K, const SE3& T) {
  auto depth = Image<float>::from_host(s.render(K, T), K.width, K.height, Device::CPU);
  vol.integrate(depth, Image<uchar3>{}, K, T);
}

// Camera sliding 6 m along the wall (z = 1.6) away from the sphere, panning a little, a frame
// every 10 cm, and back to the sphere a frame every 20 cm: the blocks left behind go to the host
// and come back to be fused again.
std::vector<SE3> path() {
  std::vector<SE3> poses;
  for (int i = 0; i <= 60; ++i) poses.push_back(test::pose({-1.f + 0.1f * i, 0.f, 0.f}, 0.1f * std::sin(0.4f * i)));
  for (int i = 1; i <= 30; ++i) poses.push_back(test::pose({5.f - 0.2f * i, 0.f, 0.f}, -0.1f));
  return poses;
}

void expect_same_blocks(const std::vector<VoxelHashVolume::HostBlock>& a,
                        const std::vector<VoxelHashVolume::HostBlock>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(a[i].coord == b[i].coord) << "block " << i;
    // The surface flag of a block streamed back in is recomputed from its voxels (mark_surface_blocks).
    ASSERT_EQ(a[i].surface, b[i].surface) << "block " << i;
    for (int k = 0; k < kernels::kBlockVoxels; ++k) {  // copies: bit-identical
      ASSERT_EQ(a[i].voxels[k].sdf16, b[i].voxels[k].sdf16);
      ASSERT_EQ(a[i].voxels[k].weight16, b[i].voxels[k].weight16);
      ASSERT_EQ(a[i].colors[k].x, b[i].colors[k].x);
      ASSERT_EQ(a[i].colors[k].y, b[i].colors[k].y);
      ASSERT_EQ(a[i].colors[k].z, b[i].colors[k].z);
    }
  }
}

std::vector<std::tuple<float, float, float>> sorted_positions(const Mesh& m) {
  std::vector<std::tuple<float, float, float>> p;
  for (vec3 v : m.positions) p.emplace_back(v.x, v.y, v.z);
  std::sort(p.begin(), p.end());
  return p;
}

TEST(VolumeStream, RoundTripKeepsEveryVoxelAndTheMesh) {
  Intrinsics K = small_camera();
  test::Scene s;
  VoxelHashVolume vol(params(4.5f), Device::CPU);
  for (const SE3& T : {test::pose({0.f, 0.f, 0.f}), test::pose({0.05f, 0.f, 0.f}, 0.1f)}) fuse(vol, s, K, T);
  const auto before = vol.download_blocks();
  const Mesh mesh_before = vol.extract_mesh();
  ASSERT_GT(before.size(), 100u);
  ASSERT_GT(mesh_before.triangles.size(), 1000u);

  // Everything is within 4.5 m of the origin and farther than that from x = 20 m.
  vol.stream({20.f, 0.f, 0.f});
  VolumeStats out = vol.stats();
  EXPECT_EQ(out.allocated_blocks, 0);
  EXPECT_EQ(out.host_blocks, static_cast<std::int64_t>(before.size()));
  EXPECT_EQ(out.host_bytes, before.size() * (sizeof(kernels::Voxel) + sizeof(uchar3)) * kernels::kBlockVoxels);
  EXPECT_TRUE(vol.download_blocks().empty());

  vol.stream({0.f, 0.f, 0.f});
  EXPECT_EQ(vol.stats().host_blocks, 0);
  expect_same_blocks(vol.download_blocks(), before);
  const Mesh mesh_after = vol.extract_mesh();
  EXPECT_EQ(mesh_after.triangles.size(), mesh_before.triangles.size());
  EXPECT_EQ(sorted_positions(mesh_after), sorted_positions(mesh_before));
}

// A pass from a point between the two ends splits the blocks by distance: each is on exactly one
// side, the device holding exactly those within the radius.
TEST(VolumeStream, EachBlockIsOnExactlyOneSide) {
  Intrinsics K = small_camera();
  test::Scene s;
  VoxelHashVolume vol(params(4.5f), Device::CPU);
  fuse(vol, s, K, SE3::identity());
  const auto all = vol.allocated_block_coords();
  const vec3 p{4.3f, 0.f, 1.6f};  // the radius passes through the fused part of the wall
  vol.stream(p);
  const auto on_device = vol.allocated_block_coords();
  std::int64_t expect_device = 0;
  for (int3 b : all) {
    vec3 c = (vec3{float(b.x), float(b.y), float(b.z)} * 8.f + vec3{3.5f, 3.5f, 3.5f}) * 0.01f;
    bool near = length(c - p) <= 4.5f;
    expect_device += near;
    EXPECT_EQ(near,
              std::binary_search(on_device.begin(), on_device.end(), b,
                                 [](int3 a, int3 b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); }))
        << "block " << b.x << " " << b.y << " " << b.z;
  }
  ASSERT_GT(expect_device, 0);
  ASSERT_LT(expect_device, static_cast<std::int64_t>(all.size()));
  EXPECT_EQ(vol.stats().host_blocks + static_cast<std::int64_t>(on_device.size()),
            static_cast<std::int64_t>(all.size()));
  vol.stream_in_all();
  EXPECT_EQ(vol.allocated_block_coords(), all);
}

// Every block a frame can touch is on the device when the frame is fused (the radius bound
// above), so streaming changes nothing that fusion computes: after bringing everything back the
// volume equals the one fused without streaming, voxel for voxel.
TEST(VolumeStream, FusingAlongAPathEqualsFusingWithoutStreaming) {
  Intrinsics K = small_camera();
  test::Scene s;
  VoxelHashVolume streamed(params(4.2f), Device::CPU), kept(params(0.f), Device::CPU);
  std::int64_t max_on_device = 0;
  for (const SE3& T : path()) {
    fuse(streamed, s, K, T);
    fuse(kept, s, K, T);
    max_on_device = std::max(max_on_device, streamed.stats().allocated_blocks);
  }
  VolumeStats st = streamed.stats();
  EXPECT_GT(st.streamed_out, 0);
  EXPECT_GT(st.streamed_in, 0);  // the way back brought blocks in before fusing them again
  EXPECT_GT(st.host_blocks, 0);
  EXPECT_LT(max_on_device, kept.stats().allocated_blocks);  // the device held only part of the model
  // The model seen from the last pose is the same (its blocks are on the device).
  SE3 last = path().back();
  EXPECT_EQ(streamed.raycast(K, last).depth.to_host(), kept.raycast(K, last).depth.to_host());
  streamed.stream_in_all();
  EXPECT_EQ(streamed.stats().host_blocks, 0);
  expect_same_blocks(streamed.download_blocks(), kept.download_blocks());
}

TEST(VolumeStream, RejectsARadiusAFrameCanReachBeyond) {
  VoxelHashVolume vol(params(3.5f), Device::CPU);
  test::Scene s;
  EXPECT_THROW(fuse(vol, s, small_camera(), SE3::identity()), Error);
}

// CPU and CUDA stream the same blocks along the path and end with the same volume (fusion values
// as in TsdfParity: float rounding only).
TEST(VolumeStreamParity, SameVolumeAfterAPath) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  Intrinsics K = small_camera();
  test::Scene s;
  VoxelHashVolume cpu(params(4.2f), Device::CPU), gpu(params(4.2f), Device::CUDA);
  for (const SE3& T : path()) {
    fuse(cpu, s, K, T);
    fuse(gpu, s, K, T);
  }
  EXPECT_EQ(cpu.stats().streamed_out, gpu.stats().streamed_out);
  EXPECT_EQ(cpu.stats().host_blocks, gpu.stats().host_blocks);
  cpu.stream_in_all();
  gpu.stream_in_all();
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(cpu.download_blocks(), gpu.download_blocks(), false));
}

}  // namespace
}  // namespace seamless
