// Voxel-hashed TSDF against analytic scenes: fused values, raycast depth and normals, garbage
// collection and capacity handling. Ground-truth poses and noise-free depth rendered in the test.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <numeric>
#include <random>
#include <tuple>

#include "core/buffer.hpp"
#include "core/cpu_simd.hpp"
#include "core/device.hpp"
#include "core/error.hpp"
#include "core/exec.hpp"
#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "kernels/recon/tsdf.hpp"
#include "kernels/recon/tsdf_fusion_simd.hpp"
#include "recon/voxel_hash_volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

using test::Scene;

// Camera translations only (no rotation), so that the projective distance to the fronto-parallel
// wall equals the true distance.
std::vector<SE3> translations() {
  return {test::pose({0.f, 0.f, 0.f}), test::pose({0.04f, 0.f, 0.f}), test::pose({-0.04f, 0.02f, 0.f}),
          test::pose({0.f, -0.03f, 0.05f}), test::pose({0.02f, 0.03f, -0.04f})};
}

void fuse(Volume& vol, const Scene& s, const Intrinsics& K, const std::vector<SE3>& poses, bool colour = false) {
  for (const SE3& T : poses) {
    std::vector<vec3> normals;
    auto depth = Image<float>::from_host(s.render(K, T, &normals), K.width, K.height, Device::CPU);
    Image<uchar3> rgb;
    if (colour) {
      std::vector<uchar3> c(normals.size());
      for (std::size_t i = 0; i < c.size(); ++i) c[i] = test::colour_of(normals[i]);
      rgb = Image<uchar3>::from_host(c, K.width, K.height, Device::CPU);
    }
    vol.integrate(depth, rgb, K, T);
  }
}

TEST(TsdfFusion, WallVoxelsHoldTheTruncatedDistance) {
  VolumeParams p = test::small_volume_params();
  VoxelHashVolume vol(p, Device::CPU);
  Scene s;
  Intrinsics K = test::camera(160, 120, 140.f);
  auto poses = translations();
  fuse(vol, s, K, poses);
  int checked = 0;
  for (const auto& blk : vol.download_blocks())
    for (int i = 0; i < kernels::kBlockVoxels; ++i) {
      const kernels::Voxel& v = blk.voxels[i];
      int3 l = kernels::local_coords(i);
      vec3 g{float(blk.coord.x * 8 + l.x), float(blk.coord.y * 8 + l.y), float(blk.coord.z * 8 + l.z)};
      vec3 w = g * p.voxel_size;
      // Seen in every frame and away from the sphere's shadow (radius r * 1.6/1.2 = 0.27 m on the
      // wall, shifted by at most 0.05 * 0.4/1.2 by the camera motion): every observation read the
      // wall depth 1.6 exactly, so the average is exactly the clamped distance.
      bool far_from_sphere = std::fabs(w.x - s.center.x) > 0.45f || std::fabs(w.y - s.center.y) > 0.45f;
      if (kernels::voxel_weight(v) < float(poses.size()) || !far_from_sphere) continue;
      float expect = std::min(s.wall_z - w.z, p.truncation);
      // The first frame stores the nearest snorm16 step (half a step, mu / 32767 / 2, from the
      // distance); the next ones observe the same distance, whose update is below half a step
      // and rounds back to it. Plus a few ulps of the 1.6 m depth in the observation.
      const float tol = 0.5f * p.truncation / kernels::kSdfSteps + 1e-6f;
      EXPECT_NEAR(kernels::voxel_sdf(v, p.truncation), expect, tol) << "voxel at " << w.x << " " << w.y << " " << w.z;
      ++checked;
    }
  EXPECT_GT(checked, 1000);
  VolumeStats st = vol.stats();
  EXPECT_EQ(st.failed_insertions, 0);
  EXPECT_GT(st.allocated_blocks, 0);
}

TEST(TsdfFusion, RaycastDepthAndNormalsMatchAnalyticScene) {
  VolumeParams p = test::small_volume_params();
  VoxelHashVolume vol(p, Device::CPU);
  Scene s;
  Intrinsics K = test::camera(320, 240, 280.f);
  std::vector<SE3> poses = translations();
  poses.push_back(test::pose({0.03f, 0.f, 0.f}, 0.05f, 0.f));
  poses.push_back(test::pose({-0.03f, 0.f, 0.f}, -0.04f, 0.03f));
  fuse(vol, s, K, poses, true);

  SE3 view = test::pose({0.01f, 0.01f, 0.02f}, 0.02f, -0.01f);  // a pose no frame was taken from
  RaycastMaps maps = vol.raycast(K, view);
  std::vector<vec3> truth_n;
  std::vector<float> truth = s.render(K, view, &truth_n);
  std::vector<float> depth = maps.depth.to_host();
  std::vector<vec3> normal = maps.normal.to_host(), vertex = maps.vertex.to_host();
  std::vector<uchar3> colour = maps.color.to_host();

  // Error bound. Fusion reads the nearest pixel, so a voxel's observed depth is off by at most
  // half a pixel's footprint times the surface slope: 0.5 * (z/f) * tan(theta) per image axis,
  // both axes: (z/f) tan(theta). We evaluate pixels with theta < 45 deg and z < 1.6 m:
  // 1.6/280 = 5.7 mm. Trilinear interpolation of the sphere's distance adds h^2/(8R) = 0.06 mm and
  // regula falsi on a near-linear field converges to well below that: bound 6 mm.
  const float tol = 1.6f / 280.f * 1.f + 0.0003f;
  int evaluated = 0, hits = 0, within = 0;
  double sum_err = 0.0;
  for (int y = 3; y < K.height - 3; ++y)
    for (int x = 3; x < K.width - 3; ++x) {
      std::size_t i = static_cast<std::size_t>(y) * K.width + x;
      vec3 ray = normalize(view.rotate(K.unproject(float(x), float(y), 1.f)));
      if (truth[i] <= 0.f || -dot(truth_n[i], ray) < std::cos(0.785f)) continue;
      // Skip depth discontinuities (the sphere's silhouette and its shadow on the wall).
      bool edge = false;
      for (int dy = -3; dy <= 3 && !edge; ++dy)
        for (int dx = -3; dx <= 3; ++dx)
          if (std::fabs(truth[i + dy * K.width + dx] - truth[i]) > 0.05f) edge = true;
      if (edge) continue;
      ++evaluated;
      if (depth[i] <= 0.f) continue;
      ++hits;
      float err = std::fabs(depth[i] - truth[i]);
      sum_err += err;
      if (err <= tol) ++within;
      EXPECT_LE(err, tol) << "pixel " << x << "," << y;
      // Normal from the TSDF gradient: the one-voxel central difference of a field sampled on a
      // 1 cm grid turns a 0.2 m sphere's normal by at most ~h/(2R) = 0.025 rad; the pixel
      // footprint adds the same order: within 0.1 rad (cos > 0.995).
      EXPECT_GT(dot(normal[i], truth_n[i]), 0.995f) << "pixel " << x << "," << y;
      vec3 truth_p = view * K.unproject(float(x), float(y), truth[i]);
      EXPECT_LE(length(vertex[i] - truth_p), tol * 1.5f);
    }
  ASSERT_GT(evaluated, 20000);
  // The evaluated pixels all lie inside the frames' common view, so the model covers them.
  EXPECT_GE(hits, evaluated * 99 / 100);
  EXPECT_EQ(within, hits);
  RecordProperty("mean_depth_error_mm", std::to_string(1000.0 * sum_err / std::max(hits, 1)));
  // Colour was fused from the normal encoding: the wall's is (127,127,0).
  std::size_t corner = static_cast<std::size_t>(20) * K.width + 20;
  ASSERT_GT(depth[corner], 0.f);
  EXPECT_NEAR(colour[corner].x, 127, 2);
  EXPECT_NEAR(colour[corner].z, 0, 2);
}

TEST(TsdfFusion, RemovingEmptyBlocksFreesThem) {
  VolumeParams p = test::small_volume_params();
  p.max_weight = 1.f;  // the model follows the newest frame: the moved wall empties the old band
  std::size_t before = memory::bytes_in_use(Device::CPU);
  VoxelHashVolume vol(p, Device::CPU);
  EXPECT_EQ(memory::bytes_in_use(Device::CPU) - before, vol.stats().device_bytes);
  Intrinsics K = test::camera(80, 60, 70.f);
  Scene near;
  near.sphere = false;
  fuse(vol, near, K, {SE3::identity()});
  auto blocks_near = vol.allocated_block_coords();
  VolumeStats s1 = vol.stats();
  EXPECT_EQ(s1.allocated_blocks, static_cast<std::int64_t>(blocks_near.size()));
  for (int3 b : blocks_near) EXPECT_NEAR(b.z * 0.08f, 1.6f, 0.16f);  // within two blocks of the wall

  // The wall moves 0.8 m back: the old band is now free space, every voxel there converges to +mu
  // (max weight 1: each frame halves the gap) and the blocks must go.
  Scene far = near;
  far.wall_z = 2.4f;
  std::vector<SE3> same(14, SE3::identity());
  fuse(vol, far, K, same);
  auto blocks_far = vol.allocated_block_coords();
  VolumeStats s2 = vol.stats();
  EXPECT_EQ(s2.allocated_blocks, static_cast<std::int64_t>(blocks_far.size()));
  for (int3 b : blocks_far) EXPECT_GT(b.z * 0.08f, 2.0f) << "block " << b.x << " " << b.y << " " << b.z;
  EXPECT_EQ(s2.voxel_bytes, s2.allocated_blocks * (sizeof(kernels::Voxel) + sizeof(uchar3)) * 512);
  EXPECT_GT(s2.tombstones, 0);
  EXPECT_EQ(s2.failed_insertions, 0);
  // Freed blocks are reused: going back to the near wall needs no growth.
  fuse(vol, near, K, same);
  VolumeStats s3 = vol.stats();
  EXPECT_EQ(s3.block_capacity, p.capacity);
  EXPECT_EQ(s3.retries, 0);
  auto blocks_back = vol.allocated_block_coords();
  for (int3 b : blocks_near)  // (the far wall's blocks stay: they are occluded, not observed empty)
    EXPECT_TRUE(std::find(blocks_back.begin(), blocks_back.end(), b) != blocks_back.end());
}

// The stand-alone pass over all blocks frees exactly the blocks without an observed voxel within
// the truncation of a surface (the predicate fusion flags per frame), and keeps the rest intact.
TEST(TsdfFusion, StandaloneRemovalFreesExactlyTheEmptyBlocks) {
  VolumeParams p = test::small_volume_params();
  p.max_weight = 1.f;
  p.remove_empty_blocks = false;  // leave the emptied band of the old wall in place
  VoxelHashVolume vol(p, Device::CPU);
  Intrinsics K = test::camera(80, 60, 70.f);
  Scene near;
  near.sphere = false;
  Scene far = near;
  far.wall_z = 2.4f;
  fuse(vol, near, K, {SE3::identity()});
  fuse(vol, far, K, std::vector<SE3>(14, SE3::identity()));
  const auto before = vol.download_blocks();
  std::vector<int3> expect_kept;
  for (const auto& blk : before) {
    bool keep = false;
    for (const kernels::Voxel& v : blk.voxels)
      keep |= kernels::voxel_observed(v) && std::fabs(kernels::voxel_sdf(v, p.truncation)) < 0.999f * p.truncation;
    if (keep) expect_kept.push_back(blk.coord);
  }
  ASSERT_LT(expect_kept.size(), before.size());  // the old band emptied
  ASSERT_GT(expect_kept.size(), 0u);
  const std::int64_t removed = vol.remove_empty_blocks();
  EXPECT_EQ(removed, static_cast<std::int64_t>(before.size() - expect_kept.size()));
  const auto after = vol.download_blocks();
  ASSERT_EQ(after.size(), expect_kept.size());
  std::size_t j = 0;
  for (const auto& blk : before) {  // both sorted by coordinate
    if (j == after.size() || !(blk.coord == after[j].coord)) continue;
    for (int k = 0; k < kernels::kBlockVoxels; ++k) ASSERT_EQ(blk.voxels[k].sdf16, after[j].voxels[k].sdf16);
    ++j;
  }
  EXPECT_EQ(j, after.size());
  EXPECT_EQ(vol.allocated_block_coords(), expect_kept);
}

TEST(TsdfFusion, FullPoolGrowsAndRetriesOrReports) {
  Intrinsics K = test::camera(160, 120, 140.f);
  Scene s;
  VolumeParams big = test::small_volume_params();
  VoxelHashVolume ref(big, Device::CPU);
  fuse(ref, s, K, {SE3::identity()});

  VolumeParams tiny = test::small_volume_params();
  tiny.capacity = 64;
  tiny.hash_buckets = 1024;
  VoxelHashVolume grown(tiny, Device::CPU);
  fuse(grown, s, K, {SE3::identity()});
  VolumeStats g = grown.stats();
  EXPECT_GT(g.retries, 0);
  EXPECT_EQ(g.failed_insertions, 0);
  EXPECT_GE(g.block_capacity, g.allocated_blocks);
  EXPECT_EQ(grown.allocated_block_coords(), ref.allocated_block_coords());

  tiny.grow_when_full = false;
  VoxelHashVolume capped(tiny, Device::CPU);
  fuse(capped, s, K, {SE3::identity()});
  VolumeStats c = capped.stats();
  EXPECT_LE(c.allocated_blocks, 64);
  EXPECT_EQ(c.block_capacity, 64);
  EXPECT_GT(c.failed_insertions, 0);  // counted and reported, not silent
}

// Growth used to stop after 4 doublings a frame, dropping the rest of the frame. A pool
// of 2 blocks and 1024 hash slots must grow as often as the first frame needs (here 2 -> 1024
// blocks and more: 9 doublings or more) and hold exactly the blocks a roomy volume allocates.
TEST(TsdfFusion, GrowthKeepsUpWithAFrameThatNeedsManyDoublings) {
  Intrinsics K = test::camera(160, 120, 140.f);
  Scene s;
  VoxelHashVolume ref(test::small_volume_params(), Device::CPU);
  fuse(ref, s, K, {SE3::identity()});
  ASSERT_GT(ref.stats().allocated_blocks, 2 << 8);  // needs more than 8 doublings of 2 blocks

  VolumeParams tiny = test::small_volume_params();
  tiny.capacity = 2;
  tiny.hash_buckets = 1024;
  VoxelHashVolume grown(tiny, Device::CPU);
  fuse(grown, s, K, {SE3::identity()});
  VolumeStats g = grown.stats();
  EXPECT_EQ(g.failed_insertions, 0);
  EXPECT_GE(g.retries, 9);
  EXPECT_EQ(grown.allocated_block_coords(), ref.allocated_block_coords());
}

// A 10,000-frame run doubled its hash table 11 times while holding at most 65,536 blocks,
// then overflowed 32-bit slot indices. Insertion never reuses tombstones, and a block that the
// truncation band only grazes (every voxel in it ends at +truncation) is allocated and freed again
// in every frame, one more tombstone before its key each time: after max_probe (128) frames its
// insertion fails in a table that is nearly empty (the between-frames rehash waits for half the
// slots to be used, which a large table never reaches). A still camera on a wall and a sphere for
// 140 frames: the table must keep its size and no insertion may fail.
TEST(TsdfFusion, BlocksFreedAndAllocatedAgainDoNotGrowTheTable) {
  VolumeParams p = test::small_volume_params();
  p.hash_buckets = 1 << 18;  // large: tombstones never fill half of it in 140 frames
  VoxelHashVolume vol(p, Device::CPU);
  Intrinsics K = test::camera(80, 60, 70.f);
  Scene s;
  fuse(vol, s, K, std::vector<SE3>(140, SE3::identity()));
  const VolumeStats st = vol.stats();
  ASSERT_LE(4 * st.allocated_blocks, st.hash_slots);  // the premise: never crowded
  EXPECT_EQ(st.hash_slots, p.hash_buckets);
  EXPECT_EQ(st.failed_insertions, 0);
  EXPECT_EQ(st.block_capacity, p.capacity);
}

// volume.capacity 0 on the CPU: a pool of 4096 blocks (14 MiB) that grows as the scan needs,
// instead of 2^18 blocks (896 MiB) reserved up front. Growing moves no voxel: the mesh
// equals that of a pool large enough from the start, vertex for vertex (sorted: the hash table's
// order of the blocks may differ).
TEST(TsdfFusion, CpuPoolStartsSmallAndGrowsToTheSameMesh) {
  VolumeParams p = test::small_volume_params();
  p.voxel_size = 0.005f, p.truncation = 0.02f, p.hash_buckets = 1 << 16;
  p.capacity = 0;
  EXPECT_EQ(p.start_capacity(false), VolumeParams::kHostStartCapacity);
  EXPECT_EQ(p.start_capacity(true), VolumeParams::kDeviceCapacity);
  VoxelHashVolume grown(p, Device::CPU);
  EXPECT_EQ(grown.stats().block_capacity, VolumeParams::kHostStartCapacity);
  VolumeParams big = p;
  big.capacity = 1 << 15;
  VoxelHashVolume roomy(big, Device::CPU);
  Scene s;
  s.wall_z = 2.9f;  // a wall filling the view (max_depth 3 m): more blocks than the small start holds
  const Intrinsics K = test::camera(240, 180, 210.f);
  const std::vector<SE3> poses = {translations()[0], translations()[1]};
  fuse(grown, s, K, poses);
  fuse(roomy, s, K, poses);
  const VolumeStats g = grown.stats(), r = roomy.stats();
  ASSERT_GT(g.allocated_blocks, VolumeParams::kHostStartCapacity);  // the premise: it had to grow
  ASSERT_LE(r.allocated_blocks, big.capacity);                      // ... and the roomy one did not
  EXPECT_EQ(r.block_capacity, big.capacity);
  EXPECT_GT(g.block_capacity, VolumeParams::kHostStartCapacity);
  EXPECT_LT(g.block_capacity, big.capacity);
  EXPECT_EQ(g.failed_insertions, 0);
  Mesh a = grown.extract_mesh(), b = roomy.extract_mesh();
  ASSERT_GT(a.positions.size(), 10000u);
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(a.triangles.size(), b.triangles.size());
  auto less = [](vec3 u, vec3 v) { return std::tie(u.x, u.y, u.z) < std::tie(v.x, v.y, v.z); };
  std::sort(a.positions.begin(), a.positions.end(), less);
  std::sort(b.positions.begin(), b.positions.end(), less);
  for (std::size_t i = 0; i < a.positions.size(); ++i) {
    ASSERT_EQ(a.positions[i].x, b.positions[i].x) << i;
    ASSERT_EQ(a.positions[i].y, b.positions[i].y) << i;
    ASSERT_EQ(a.positions[i].z, b.positions[i].z) << i;
  }

  // Without growth the CPU cannot start small: it starts as large as on CUDA.
  p.grow_when_full = false;
  EXPECT_EQ(p.start_capacity(false), VolumeParams::kDeviceCapacity);
}

TEST(TsdfFusion, RejectsTruncationBelowTwoVoxels) {
  VolumeParams p = test::small_volume_params();
  p.truncation = 0.015f;
  EXPECT_THROW((VoxelHashVolume{p, Device::CPU}), Error);
}

// CPU and CUDA fuse the same frames into the same block set with the same values: the kernels are
// one source, so only float rounding (FMA contraction on the GPU) may differ, far below 1e-5 m.
// Culling by depth tiles (volume.occlusion_tile) leaves out only blocks that the frame cannot change
// (kernels/recon/tsdf_fusion.inl, block_maybe_visible): fusing with and without it must give the
// same blocks with the same values. The camera swings round the sphere, so that wall blocks fused
// from one side are hidden behind it from the other, and must be culled (fewer listed blocks).
TEST(TsdfFusion, CullingOccludedBlocksChangesNothing) {
  Intrinsics K = test::camera(160, 120, 140.f);
  Scene s;
  std::vector<SE3> poses = {test::pose({-0.3f, 0.f, 0.f}, 0.2f), test::pose({0.f, 0.f, 0.f}),
                            test::pose({0.3f, 0.05f, 0.f}, -0.2f, 0.05f), test::pose({-0.1f, -0.05f, 0.1f}, 0.1f)};
  VolumeParams culled = test::small_volume_params(), full = culled;
  full.occlusion_tile = 0;
  VoxelHashVolume a(culled, Device::CPU), b(full, Device::CPU);
  std::int64_t listed_a = 0, listed_b = 0;
  for (const SE3& T : poses) {
    fuse(a, s, K, {T}, true);
    fuse(b, s, K, {T}, true);
    EXPECT_LE(a.stats().visible_blocks, b.stats().visible_blocks);
    listed_a += a.stats().visible_blocks, listed_b += b.stats().visible_blocks;
  }
  EXPECT_LT(listed_a, listed_b);
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(a.download_blocks(), b.download_blocks(), true));
}

// The first n frames of tum_fr1_rpy_000-149 (ground-truth poses in them) for the real-frame tests
// below, or why they cannot be read here in *skip.
InputParams real_test_frames(int n, std::string* skip) {
  InputParams in;
  in.source = InputSource::tum;
  in.path = std::string(SEAMLESS_TEST_DATA) + "/tum_fr1_rpy_000-149";
  in.max_frames = n;
  if (!std::filesystem::exists(in.path)) *skip = "no test data at " + in.path;
  return in;
}

// The same on real Kinect frames (tum_fr1_rpy, ground-truth poses, 1 cm voxels for speed): holes,
// far noisy depth and grazing surfaces included, culling leaves the fused blocks as they were.
TEST(TsdfFusion, CullingChangesNothingOnRealFrames) {
  std::string skip;
  const InputParams in = real_test_frames(12, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  auto src = make_source(in, Device::CPU);
  VolumeParams culled;
  culled.voxel_size = 0.01f, culled.truncation = 0.04f;
  VolumeParams full = culled;
  full.occlusion_tile = 0;
  VoxelHashVolume a(culled, Device::CPU), b(full, Device::CPU);
  RgbdFrame f;
  std::int64_t listed_a = 0, listed_b = 0;
  while (src->next(f)) {
    ASSERT_TRUE(f.ground_truth.has_value());
    a.integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
    b.integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
    listed_a += a.stats().visible_blocks, listed_b += b.stats().visible_blocks;
  }
  EXPECT_LT(listed_a, listed_b);
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(a.download_blocks(), b.download_blocks(), true));
}

// Allocation skips the table's probes for the blocks the last raycast's window holds: on real
// Kinect frames (ground-truth poses, 1 cm voxels for speed), a volume raycast after every frame
// must end with the blocks and voxels of one without a window, also when blocks are freed between
// the raycast and the next frame (remove_empty_blocks), which the window must then not vouch for.
void same_blocks_with_and_without_the_window(Device dev) {
  std::string skip;
  const InputParams in = real_test_frames(8, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  auto src = make_source(in, Device::CPU);
  VolumeParams with;
  with.voxel_size = 0.01f, with.truncation = 0.04f;
  with.remove_empty_blocks = false;  // freed by the calls below instead, after the raycast
  VolumeParams without = with;
  without.raycast_window = 0;
  VoxelHashVolume a(with, dev), b(without, dev);
  RgbdFrame f;
  std::int64_t freed = 0;
  while (src->next(f)) {
    ASSERT_TRUE(f.ground_truth.has_value());
    for (VoxelHashVolume* v : {&a, &b}) {
      v->integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
      v->raycast(src->intrinsics(), *f.ground_truth);
    }
    const std::int64_t n = a.remove_empty_blocks();
    ASSERT_EQ(n, b.remove_empty_blocks());
    freed += n;
  }
  EXPECT_GT(freed, 0);  // blocks left the table while a window held them
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(a.download_blocks(), b.download_blocks(), true));
}

TEST(TsdfFusion, AllocationThroughTheRaycastWindowChangesNothing) {
  same_blocks_with_and_without_the_window(Device::CPU);
}

TEST(TsdfParity, AllocationThroughTheRaycastWindowOnCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  same_blocks_with_and_without_the_window(Device::CUDA);
}

// The CPU fuses a block row on 8 SIMD lanes (kernels/recon/tsdf_fusion_simd.hpp) with the scalar
// loop's expressions in its order: on real Kinect frames (ground-truth poses, 1 cm voxels for
// speed; holes, far noisy depth and the image border included) the voxels, colours, kept blocks and
// surface flags must be those of the scalar loop bit for bit, in a band-only volume and in one
// that stores free space (its surface flags).
// The first n frames of tum_fr1_rpy_000-149 for the SIMD tests below, or why they cannot run
// here (no AVX2, no data) in *skip.
InputParams simd_test_frames(int n, std::string* skip) {
  const InputParams in = real_test_frames(n, skip);
  if (!simd::cpu_simd()) *skip = "this CPU has no AVX2: the SIMD lanes do not run";
  return in;
}

TEST(TsdfFusion, SimdRowsGiveTheScalarLoopsVoxelsBitForBit) {
  std::string skip;
  const InputParams in = simd_test_frames(8, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  VolumeParams p;
  p.voxel_size = 0.01f, p.truncation = 0.04f;
  for (bool free_space : {false, true}) {
    VoxelHashVolume simd(p, Device::CPU), scalar(p, Device::CPU);
    simd.set_free_space_storage(free_space), scalar.set_free_space_storage(free_space);
    auto src = make_source(in, Device::CPU);
    RgbdFrame f;
    while (src->next(f)) {
      ASSERT_TRUE(f.ground_truth.has_value());
      simd::set_cpu_simd(true);
      simd.integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
      simd::set_cpu_simd(false);
      scalar.integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
    }
    simd::set_cpu_simd(true);
    const auto a = simd.download_blocks(), b = scalar.download_blocks();
    ASSERT_EQ(a.size(), b.size()) << "free space " << free_space;
    std::int64_t observed = 0, coloured = 0, flagged = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_TRUE(a[i].coord == b[i].coord);
      ASSERT_EQ(a[i].surface, b[i].surface);
      ASSERT_EQ(a[i].voxels.size(), b[i].voxels.size());
      ASSERT_EQ(std::memcmp(a[i].voxels.data(), b[i].voxels.data(), a[i].voxels.size() * sizeof(kernels::Voxel)), 0);
      ASSERT_EQ(std::memcmp(a[i].colors.data(), b[i].colors.data(), a[i].colors.size() * sizeof(uchar3)), 0);
      for (const auto& v : a[i].voxels) observed += v.weight16 > 1;
      for (const auto& c : a[i].colors) coloured += c.x + c.y + c.z > 0;
      flagged += a[i].surface;
    }
    // The frames were fused, several times over, with colour, and some blocks are flagged and
    // some not where free space is stored (so both sides of each comparison occur).
    EXPECT_GT(observed, 100000) << "free space " << free_space;
    EXPECT_GT(coloured, 10000) << "free space " << free_space;
    EXPECT_GT(flagged, 100) << "free space " << free_space;
    if (free_space) {
      EXPECT_LT(flagged, static_cast<std::int64_t>(a.size()));
    }
  }
}

// Allocation sets up the walks over 8 pixels' truncation bands on SIMD lanes
// (detail::band_walks_simd): on real Kinect frames at their ground-truth poses, 5 mm voxels, every
// pixel's walk must be band_walk's bit for bit, and exactly the pixels with a reading in range (and
// inside the image: the last group of a row is cut at its width) get one.
TEST(TsdfFusion, SimdBandWalksAreTheScalarWalksBitForBit) {
  std::string skip;
  const InputParams in = simd_test_frames(3, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  auto src = make_source(in, Device::CPU);
  const kernels::VoxelGeometry geom{{0.1f, -0.2f, 0.3f}, 0.005f, 0.02f};
  RgbdFrame f;
  std::int64_t walks = 0, long_walks = 0, differ = 0;
  while (src->next(f)) {
    ASSERT_TRUE(f.ground_truth.has_value());
    kernels::FrameInput fi{f.depth.cview(), {}, src->intrinsics(), *f.ground_truth};
    const int w = fi.depth.width, h = fi.depth.height;
    for (int y = 0; y < h; ++y)
      for (int x0 = 0; x0 < w + 5; x0 += 8) {  // and past the width: 8-wide groups from x0 = w + 4
        kernels::BlockWalk lanes[8];
        const int got = kernels::detail::band_walks_simd(fi, geom, x0, y, lanes);
        for (int l = 0; l < 8; ++l) {
          const int x = x0 + l;
          const bool wanted = x < w && fi.depth(x, y) >= fi.min_depth && fi.depth(x, y) <= fi.max_depth;
          ASSERT_EQ((got >> l & 1) != 0, wanted) << "pixel " << x << ", " << y;
          if (!wanted) continue;
          const kernels::BlockWalk s = kernels::band_walk(fi, geom, x, y, fi.depth(x, y));
          differ += std::memcmp(&s, &lanes[l], sizeof s) != 0;
          ++walks;
          long_walks += !(s.c == s.e);
        }
      }
  }
  EXPECT_EQ(differ, 0) << "of " << walks << " walks";
  EXPECT_GT(walks, 500000);          // three frames' readings
  EXPECT_GT(long_walks, walks / 4);  // bands that cross block faces: the t and dt of the walk matter
}

// The CPU's march on SIMD lanes (kernels/recon/tsdf_march_simd.hpp; its normal map, from the
// vertex map's neighbours, on lanes too) against the scalar march and normals, on
// a model of 3 real fr1_rpy frames at 1 cm: depth, vertex, normal and colour maps bit for bit,
// from each frame's pose and from 1.5 m behind it (longer rays, through more of the block window's
// edge), with the window over the frustum and cut down to 2 blocks (most lookups then fall back to
// the hash table), and with free space stored (the march's near-surface flags) or not.
TEST(TsdfRaycast, SimdMarchGivesTheScalarMarchsMapsBitForBit) {
  std::string skip;
  const InputParams in = simd_test_frames(3, &skip);
  if (!skip.empty()) GTEST_SKIP() << skip;
  for (bool free_space : {false, true})
    for (int window : {VolumeParams{}.raycast_window, 2}) {
      VolumeParams p;
      p.voxel_size = 0.01f, p.truncation = 0.04f;
      p.raycast_window = window;
      VoxelHashVolume vol(p, Device::CPU);
      vol.set_free_space_storage(free_space);
      auto src = make_source(in, Device::CPU);
      std::vector<SE3> poses;
      RgbdFrame f;
      while (src->next(f)) {
        ASSERT_TRUE(f.ground_truth.has_value());
        vol.integrate(f.depth, f.rgb, src->intrinsics(), *f.ground_truth);
        poses.push_back(*f.ground_truth);
        SE3 back = *f.ground_truth;
        back.t = back.t - back.rotate(vec3{0.f, 0.f, 1.5f});
        poses.push_back(back);
      }
      std::int64_t hits = 0, misses = 0;
      for (const SE3& pose : poses) {
        simd::set_cpu_simd(true);
        const RaycastMaps a = vol.raycast(src->intrinsics(), pose);
        simd::set_cpu_simd(false);
        const RaycastMaps b = vol.raycast(src->intrinsics(), pose);
        simd::set_cpu_simd(true);
        const std::string what = "free space " + std::to_string(free_space) + ", window " + std::to_string(window);
        const auto da = a.depth.to_host(), db = b.depth.to_host();
        ASSERT_EQ(std::memcmp(da.data(), db.data(), da.size() * sizeof(float)), 0) << what;
        const auto va = a.vertex.to_host(), vb = b.vertex.to_host(), na = a.normal.to_host(), nb = b.normal.to_host();
        ASSERT_EQ(std::memcmp(va.data(), vb.data(), va.size() * sizeof(vec3)), 0) << what;
        ASSERT_EQ(std::memcmp(na.data(), nb.data(), na.size() * sizeof(vec3)), 0) << what;
        const auto ca = a.color.to_host(), cb = b.color.to_host();
        ASSERT_EQ(std::memcmp(ca.data(), cb.data(), ca.size() * sizeof(uchar3)), 0) << what;
        for (float d : da) (d > 0.f ? hits : misses) += 1;
      }
      // Both outcomes occur: the desk fills much of every view (over 40 % of the rays hit it, the
      // views from behind included), and some rays pass beside the model.
      EXPECT_GT(hits, static_cast<std::int64_t>(poses.size()) * 640 * 480 / 4);
      EXPECT_GT(misses, 1000);
    }
}

namespace {

// A wall 2 m in front of the camera, fused three times from the origin with the free space stored
// or not (Volume::set_free_space_storage). max_depth 2.1 m makes the free-space rays' stride 7
// pixels (kernels::free_space_stride: floor(8 cm * 280 / (sqrt(2) * 2.1 m))), 5 cm apart at the
// wall, just under the 5.66 cm (a block over sqrt(2)) that hits every block.
VoxelHashVolume wall_seen_three_times(bool store_free_space) {
  VolumeParams p = test::small_volume_params();
  p.truncation = 0.04f, p.max_depth = 2.1f;
  VoxelHashVolume vol(p, Device::CPU);
  vol.set_free_space_storage(store_free_space);
  const Intrinsics K = test::camera(160, 120, 280.f);
  EXPECT_EQ(kernels::free_space_stride(K.fx, p.max_depth, {{0.f, 0.f, 0.f}, p.voxel_size, p.truncation}), 7);
  const auto depth = Image<float>::from_host(std::vector<float>(160 * 120, 2.f), 160, 120, Device::CPU);
  for (int f = 0; f < 3; ++f) vol.integrate(depth, Image<uchar3>(), K, SE3::identity());
  return vol;
}

// Blocks wholly in the camera's view (every corner of the box [8b, 8b + 8] projects a pixel or more
// inside the image) and wholly between 0.3 m and 1.88 m deep, a block clear of the wall's band
// [1.96, 2.04] m: only rays in front of the wall reach them.
bool in_front_of_the_wall(int3 b) {
  const Intrinsics K = test::camera(160, 120, 280.f);
  for (int k = 0; k < 8; ++k) {
    const vec3 c{(b.x * 8 + (k & 1) * 8) * 0.01f, (b.y * 8 + ((k >> 1) & 1) * 8) * 0.01f,
                 (b.z * 8 + (k >> 2) * 8) * 0.01f};
    if (c.z < 0.3f || c.z > 1.88f) return false;
    const vec2 uv = K.project(c);
    if (uv.x < 1.f || uv.x > K.width - 2.f || uv.y < 1.f || uv.y > K.height - 2.f) return false;
  }
  return true;
}

}  // namespace

// Stored free space: every block in front of the wall in the view is allocated, each of its voxels
// fused three times with +truncation (every ray passed it on its way to the wall, 12 cm or more
// beyond), and none is freed as empty, per frame or by the stand-alone pass. Without it, none of
// those blocks exists.
TEST(TsdfFusion, StoredFreeSpaceFillsTheViewInFrontOfTheWall) {
  VoxelHashVolume vol = wall_seen_three_times(true);
  int front = 0;
  for (int bz = 3; bz < 24; ++bz)
    for (int by = -8; by < 8; ++by)
      for (int bx = -8; bx < 8; ++bx) front += in_front_of_the_wall({bx, by, bz});
  ASSERT_GT(front, 300);
  int found = 0;
  for (const auto& blk : vol.download_blocks()) {
    if (!in_front_of_the_wall(blk.coord)) continue;
    ++found;
    for (const kernels::Voxel& v : blk.voxels) {
      ASSERT_EQ(v.weight16, 3);
      ASSERT_EQ(v.sdf16, 32767);  // +truncation, the last step exactly: mu / mu * 32767 each frame
    }
  }
  EXPECT_EQ(found, front);
  EXPECT_EQ(vol.stats().failed_insertions, 0);
  EXPECT_EQ(vol.remove_empty_blocks(), 0);
  VoxelHashVolume band_only = wall_seen_three_times(false);
  for (int3 b : band_only.allocated_block_coords()) EXPECT_FALSE(in_front_of_the_wall(b));
  EXPECT_LE(band_only.stats().allocated_blocks + front, vol.stats().allocated_blocks);
}

// Whether block b has a voxel fused near a surface: observed, |sdf| below 0.999 truncation (the
// surface flag's definition, kernels::SurfaceFlags, evaluated on the downloaded voxels).
bool has_voxel_near_surface(const VoxelHashVolume::HostBlock& b, float truncation) {
  for (const kernels::Voxel& v : b.voxels)
    if (kernels::voxel_observed(v) && std::fabs(kernels::voxel_sdf(v, truncation)) < 0.999f * truncation) return true;
  return false;
}

// The surface flag (kernels::SurfaceFlags) on the wall seen three times: with or without the
// free space stored, every block's flag is its definition evaluated on its voxels, no block in
// front of the wall has it, and the flagged blocks of the volume storing free space are exactly
// the blocks of the band-only volume, whose garbage collection keeps just the blocks with a
// voxel near a surface (every block there is crossed by some pixel's band: rays 0.7 cm apart at
// the wall, blocks of 8 cm).
TEST(TsdfFusion, SurfaceFlagMarksTheWallsBlocks) {
  VoxelHashVolume vol = wall_seen_three_times(true), band = wall_seen_three_times(false);
  std::vector<int3> flagged, band_blocks;
  for (const auto& b : vol.download_blocks()) {
    ASSERT_EQ(b.surface, has_voxel_near_surface(b, 0.04f)) << b.coord.x << "," << b.coord.y << "," << b.coord.z;
    if (in_front_of_the_wall(b.coord)) {
      ASSERT_FALSE(b.surface) << b.coord.x << "," << b.coord.y << "," << b.coord.z;
    }
    if (b.surface) flagged.push_back(b.coord);
  }
  for (const auto& b : band.download_blocks()) {
    ASSERT_TRUE(b.surface) << "garbage collection keeps only blocks near a surface";
    ASSERT_TRUE(has_voxel_near_surface(b, 0.04f));
    band_blocks.push_back(b.coord);
  }
  ASSERT_GT(band_blocks.size(), 300u);
  EXPECT_EQ(flagged, band_blocks);  // both sorted by coordinate (download_blocks)
}

// The raycast through the stored free space, which skips the blocks not near a surface, against
// the band-only volume's and the truth. The wall is fronto-parallel to the fusing camera, so every
// voxel holds min(2 m - z, truncation) (the projective distance is the true one): linear in the
// band, where the trilinear interpolation reproduces it and regula falsi lands on its zero, so
// both volumes give the wall's depth to float rounding at 2 m (an ulp is 2.4e-7 m; 1e-6 allowed),
// seen from the fusing camera and from one moved inside the fused view. Pixels within 2 of the
// image border are left out: their rays run along the fused frustum's edge, where cells are
// partly unobserved and the march's unobserved steps decide, differently where the samples differ.
TEST(TsdfFusion, RaycastThroughStoredFreeSpaceFindsTheWall) {
  VoxelHashVolume vol = wall_seen_three_times(true), band = wall_seen_three_times(false);
  const Intrinsics K = test::camera(160, 120, 280.f);
  Scene s;
  s.wall_z = 2.f, s.sphere = false;
  for (const SE3& v : {SE3::identity(), test::pose({0.05f, 0.02f, 0.4f}, 0.02f, 0.02f)}) {
    const RaycastMaps a = vol.raycast(K, v), b = band.raycast(K, v);
    const auto da = a.depth.to_host(), db = b.depth.to_host(), truth = s.render(K, v);
    const auto na = a.normal.to_host(), nb = b.normal.to_host();
    int compared = 0;
    for (int y = 2; y < K.height - 2; ++y)
      for (int x = 2; x < K.width - 2; ++x) {
        const std::size_t i = static_cast<std::size_t>(y) * K.width + x;
        ASSERT_GT(da[i], 0.f) << x << "," << y;
        ASSERT_GT(db[i], 0.f) << x << "," << y;
        ASSERT_NEAR(da[i], truth[i], 1e-6f) << x << "," << y;
        ASSERT_NEAR(db[i], truth[i], 1e-6f) << x << "," << y;
        // Normals from neighbouring vertices of the same plane: the wall's, facing the camera.
        ASSERT_LT(na[i].z, -0.99999f) << x << "," << y;
        ASSERT_LT(nb[i].z, -0.99999f) << x << "," << y;
        ++compared;
      }
    EXPECT_EQ(compared, (K.width - 4) * (K.height - 4));
  }
}

// The free-space rays on CUDA against the CPU: the same blocks and voxels.
TEST(TsdfParity, StoredFreeSpace) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  Intrinsics K = test::camera(320, 240, 280.f);
  Scene s;
  VoxelHashVolume cpu(test::small_volume_params(), Device::CPU), gpu(test::small_volume_params(), Device::CUDA);
  cpu.set_free_space_storage(true), gpu.set_free_space_storage(true);
  fuse(cpu, s, K, translations(), true);
  fuse(gpu, s, K, translations(), true);
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(cpu.download_blocks(), gpu.download_blocks(), true));
  EXPECT_EQ(cpu.stats().allocated_blocks, gpu.stats().allocated_blocks);
}

// The surface flags and the raycast through the stored free space on CUDA against the CPU. The
// voxels agree to 1e-5 m (expect_same_blocks), and each backend's flags are their definition on
// its own voxels (the same float comparison), so the flags differ at most where a voxel lies
// within 1e-5 m of the threshold. The raycast, with the ray intervals (whose pass also marks the
// blocks near a surface) and without (mark_near_surface), as TsdfParity.SameBlocksAndValues
// compares it: a ray grazing a block edge may go either way, depths within 1e-4 m.
TEST(TsdfParity, SurfaceFlagsAndRaycastWithStoredFreeSpace) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  const Intrinsics K = test::camera(320, 240, 280.f);
  Scene s;
  std::vector<SE3> poses = translations();
  poses.push_back(test::pose({0.03f, 0.f, 0.f}, 0.05f, 0.f));
  for (int tile : {8, 0}) {
    VolumeParams p = test::small_volume_params();
    p.raycast_tile = tile;
    VoxelHashVolume cpu(p, Device::CPU), gpu(p, Device::CUDA);
    cpu.set_free_space_storage(true), gpu.set_free_space_storage(true);
    fuse(cpu, s, K, poses, true);
    fuse(gpu, s, K, poses, true);
    const auto a = cpu.download_blocks(), b = gpu.download_blocks();
    ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(a, b, true));
    int flagged = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].surface, has_voxel_near_surface(a[i], p.truncation)) << "cpu block " << i;
      ASSERT_EQ(b[i].surface, has_voxel_near_surface(b[i], p.truncation)) << "cuda block " << i;
      flagged += a[i].surface;
    }
    EXPECT_GT(flagged, 0);
    EXPECT_LT(flagged, static_cast<int>(a.size()) / 2);  // most stored blocks are free space
    const SE3 view = test::pose({0.01f, 0.01f, 0.02f}, 0.02f, -0.01f);
    const auto da = cpu.raycast(K, view).depth.to_host(), db = gpu.raycast(K, view).depth.to_host();
    int differ = 0, hits = 0;
    for (std::size_t i = 0; i < da.size(); ++i) {
      if ((da[i] > 0.f) != (db[i] > 0.f)) ++differ;
      else EXPECT_NEAR(da[i], db[i], 1e-4f);
      hits += da[i] > 0.f;
    }
    EXPECT_LE(differ, int(da.size() / 1000)) << "tile " << tile;
    EXPECT_GT(hits, int(da.size() / 2)) << "tile " << tile;
  }
}

// sort_visible_by_block on dev: a shuffled list of the slots of 1000 blocks with distinct pool
// indices comes back as the same slots, ordered by their block's index.
void expect_visible_sorted_by_block(Device dev) {
  const int slots = 4096, listed = 1000;
  std::mt19937 rng(3);
  std::vector<std::int32_t> values(slots, -1), blocks(slots);
  std::iota(blocks.begin(), blocks.end(), 0);
  std::shuffle(blocks.begin(), blocks.end(), rng);
  std::vector<std::int32_t> list(slots);
  std::iota(list.begin(), list.end(), 0);
  std::shuffle(list.begin(), list.end(), rng);
  list.resize(listed);
  for (std::int32_t s : list) values[s] = blocks[s];
  auto v = Buffer<std::int32_t>::from_host(values, dev);
  auto l = Buffer<std::int32_t>::from_host(list, dev);
  Buffer<std::int32_t> keys(listed, dev);
  kernels::HashTableView t{nullptr, v.data(), static_cast<std::uint32_t>(slots - 1)};
  with_exec(dev, [&]<class E>(const E& ex) {
    kernels::TsdfFusion<E>::sort_visible_by_block(ex, t, l.view(), listed, keys.view(), 12);
  });
  const auto sorted = l.to_host();
  for (int j = 1; j < listed; ++j) ASSERT_LT(values[sorted[j - 1]], values[sorted[j]]) << j;
  auto a = sorted, b = list;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  EXPECT_EQ(a, b);
}

TEST(TsdfFusion, VisibleListSortsByBlockIndex) { expect_visible_sorted_by_block(Device::CPU); }

TEST(TsdfParity, VisibleListSortsByBlockIndexOnCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  expect_visible_sorted_by_block(Device::CUDA);
}

TEST(TsdfParity, SameBlocksAndValues) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  Intrinsics K = test::camera(320, 240, 280.f);
  Scene s;
  std::vector<SE3> poses = translations();
  poses.push_back(test::pose({0.03f, 0.f, 0.f}, 0.05f, 0.f));
  VoxelHashVolume cpu(test::small_volume_params(), Device::CPU), gpu(test::small_volume_params(), Device::CUDA);
  fuse(cpu, s, K, poses, true);
  fuse(gpu, s, K, poses, true);
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(cpu.download_blocks(), gpu.download_blocks(), true));
  SE3 view = test::pose({0.01f, 0.01f, 0.02f}, 0.02f, -0.01f);
  auto da = cpu.raycast(K, view).depth.to_host(), db = gpu.raycast(K, view).depth.to_host();
  int differ = 0;
  for (std::size_t i = 0; i < da.size(); ++i) {
    if ((da[i] > 0.f) != (db[i] > 0.f)) ++differ;
    else EXPECT_NEAR(da[i], db[i], 1e-4f);
  }
  EXPECT_LE(differ, int(da.size() / 1000));  // a ray grazing a block edge may go either way
  EXPECT_EQ(cpu.stats().allocated_blocks, gpu.stats().allocated_blocks);
}

}  // namespace
// The 4-byte voxel's encoding (kernels::Voxel): a distance stored and read back is the nearest
// snorm16 step, within half a step of mu / 32767 (plus the float roundings of the conversions, a
// few 32767 * 2^-24 steps: under a hundredth); distances beyond the truncation clamp to it; the weight is an exact
// count.
TEST(VoxelEncoding, RoundTripWithinHalfAStep) {
  const float mu = 0.02f, step = mu / kernels::kSdfSteps;
  constexpr int n = 200001;
  for (int i = 0; i < n; ++i) {
    const float sdf = mu * (2.f * static_cast<float>(i) / (n - 1) - 1.f);
    const kernels::Voxel v = kernels::make_voxel(sdf, mu, 1.f);
    ASSERT_LE(std::fabs(kernels::voxel_sdf(v, mu) - sdf), 0.51f * step) << sdf;
  }
  EXPECT_EQ(kernels::make_voxel(mu, mu, 1.f).sdf16, 32767);
  EXPECT_EQ(kernels::make_voxel(-mu, mu, 1.f).sdf16, -32767);
  EXPECT_EQ(kernels::make_voxel(3.f * mu, mu, 1.f).sdf16, 32767);
  EXPECT_EQ(kernels::make_voxel(-3.f * mu, mu, 1.f).sdf16, -32767);
  EXPECT_FLOAT_EQ(kernels::voxel_sdf(kernels::make_voxel(mu, mu, 1.f), mu), mu);
  for (int w : {0, 1, 100, 65535}) EXPECT_EQ(kernels::voxel_weight(kernels::make_voxel(0.f, mu, float(w))), float(w));
  EXPECT_FALSE(kernels::voxel_observed(kernels::Voxel{0, 0}));
}

// The running average at the weight cap still follows its input: a voxel at -mu with the default
// cap of 100 sees a constant +0.3 mu for 3000 frames. The exact average x_n approaches it as
// (100/101)^n; the stored q_n = round(q + (t - q) / 101) differs from it by e_{n+1} = e_n 100/101
// + r with |r| <= 1/2 step, so |e_n| <= 101/2 steps at every frame, and at the end q is within
// 101/2 steps of t. Truncating instead of rounding would stall 101 steps short of t (a change
// under one step dropped), beyond the bound. The count saturates at the cap (no wrap at 2^16).
TEST(VoxelEncoding, RunningAverageConvergesAtTheWeightCap) {
  const float mu = 0.02f, cap = 100.f, t = 0.3f * mu;
  const double S = kernels::kSdfSteps;
  kernels::Voxel v = kernels::make_voxel(-mu, mu, cap);
  double x = -S;  // the exact running average, in steps
  const double bound = (cap + 1.) / 2. + 1e-3;
  for (int n = 0; n < 3000; ++n) {
    kernels::fuse_tsdf(v, t, mu, cap);
    x += (t / mu * S - x) / (cap + 1.);
    ASSERT_EQ(v.weight16, 100);
    ASSERT_LE(std::fabs(v.sdf16 - x), bound) << "frame " << n;
  }
  EXPECT_LE(std::fabs(v.sdf16 - t / mu * S), bound);
  EXPECT_GT(v.sdf16, 0);  // moved the whole way from -mu
  // From the other side the same.
  v = kernels::make_voxel(mu, mu, cap);
  for (int n = 0; n < 3000; ++n) kernels::fuse_tsdf(v, t, mu, cap);
  EXPECT_LE(std::fabs(v.sdf16 - t / mu * S), bound);

  const float most = kernels::kMaxVoxelWeight;
  kernels::Voxel full = kernels::make_voxel(0.f, mu, most - 1.f);
  for (int n = 0; n < 3; ++n) kernels::fuse_tsdf(full, 0.f, mu, most);
  EXPECT_EQ(kernels::voxel_weight(full), most);
}

// volume.max_weight must fit the 16-bit count: a whole number (checked by validate) up to 65535
// (the key's range).
TEST(VoxelEncoding, MaxWeightMustBeAWholeCount) {
  VolumeParams p;
  p.max_weight = 100.5f;
  EXPECT_THROW(p.validate(), ConfigError);
  p.max_weight = 65535.f;
  EXPECT_NO_THROW(p.validate());
}

}  // namespace seamless
