// Ray-interval raycasting (Niessner et al. 2013, section 4.3) against the plain march from
// min_depth: the same surfaces from the same model, seen from views that put blocks across the
// near plane, partly outside the image, and behind surfaces.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/exec.hpp"
#include "kernels/recon/tsdf.hpp"
#include "recon/voxel_hash_volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

VolumeParams params_with_tile(int tile) {
  VolumeParams p = test::small_volume_params();
  p.capacity = 8192;
  p.raycast_tile = tile;
  return p;
}

test::Scene scene() {
  test::Scene s;
  s.box = true;  // box in front of the sphere's lower half: occlusions and depth jumps in one tile
  s.box_lo = {-0.35f, 0.05f, 0.85f};
  s.box_hi = {-0.05f, 0.25f, 1.05f};
  return s;
}

void fuse(Volume& vol, const test::Scene& s, const Intrinsics& K) {
  const SE3 poses[] = {test::pose({0.f, 0.f, 0.f}), test::pose({0.1f, 0.f, 0.f}, 0.15f, 0.f),
                       test::pose({-0.1f, 0.05f, 0.f}, -0.15f, 0.05f), test::pose({0.f, -0.1f, 0.1f}, 0.f, -0.1f)};
  for (const SE3& T : poses) {
    auto depth = Image<float>::from_host(s.render(K, T), K.width, K.height, Device::CPU);
    vol.integrate(depth, Image<uchar3>{}, K, T);
  }
}

struct Views {
  const char* name;
  SE3 pose;
  bool sees_front;  // whether the view sees front faces (else only the backs: -/+ crossings, no hits)
};

// Rays of the interval march start before their tile's first block, in unallocated blocks that
// the plain march also skips block by block to the same exit points (z = block exit + 0.05 voxel
// along the ray), so both take identical samples from the first allocated block on: identical
// hits and bit-identical depths. The only exception is a ray that clips the block it starts in
// for less than that 0.05-voxel skip, which the plain march steps over: its samples in the next
// block start up to 0.05 voxel apart, and the refined crossings of the same zero surface then
// differ by the regula falsi residual (far below a millimetre), not by a surface. Such rays pass
// within 0.05 voxel of a block edge: at most 2 edges x 0.05 / 8 voxels ~ 1.3% of the rays that
// enter a block; we allow 2% non-identical depths, each within 1 mm, and no hit/miss change.
void expect_same_surfaces(const RaycastMaps& plain, const RaycastMaps& tiled, const std::string& what,
                          bool sees_front) {
  auto dp = plain.depth.to_host(), dt = tiled.depth.to_host();
  auto np = plain.normal.to_host(), nt = tiled.normal.to_host();
  int hits = 0, hit_mismatch = 0, not_identical = 0;
  for (std::size_t i = 0; i < dp.size(); ++i) {
    if ((dp[i] > 0.f) != (dt[i] > 0.f)) {
      ++hit_mismatch;
      continue;
    }
    if (dp[i] <= 0.f) continue;
    ++hits;
    if (dp[i] != dt[i]) ++not_identical;
    EXPECT_NEAR(dp[i], dt[i], 1e-3f) << what << " pixel " << i;
    // Normals come from neighbouring hits (vertex_map_normal): a hit with no usable neighbour has
    // none, in both maps alike.
    const bool none_p = length2(np[i]) == 0.f, none_t = length2(nt[i]) == 0.f;
    EXPECT_EQ(none_p, none_t) << what << " pixel " << i;
    if (!none_p && !none_t) {
      EXPECT_GT(dot(np[i], nt[i]), 0.99f) << what << " pixel " << i;
    }
  }
  EXPECT_EQ(hit_mismatch, 0) << what;
  EXPECT_LE(not_identical, hits / 50) << what;
  if (sees_front) {
    EXPECT_GT(hits, static_cast<int>(dp.size()) / 4) << what << ": the view must see the model";
  }
  ::testing::Test::RecordProperty(what + "_not_identical", std::to_string(not_identical));
}

TEST(TsdfRaycastIntervals, HitTheSameSurfacesAsThePlainMarch) {
  Intrinsics K = test::camera(200, 150, 170.f);
  test::Scene s = scene();
  VoxelHashVolume plain(params_with_tile(0), Device::CPU);
  fuse(plain, s, K);
  const Views views[] = {
      {"unseen_pose", test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), true},
      // The box's front face 0.3 m away, the sphere 0.45 m: blocks straddle the 0.2 m near plane.
      {"close_up", test::pose({-0.15f, 0.1f, 0.55f}), true},
      // Half the image looks past the fused region.
      {"turned", test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f), true},
      // From behind the wall looking back: rays enter the band from the back of the surface.
      {"behind_wall", test::pose({0.f, 0.f, 2.0f}, 3.14159265f, 0.f), false},
  };
  for (int tile : {1, 8, 32}) {
    VoxelHashVolume tiled(params_with_tile(tile), Device::CPU);
    fuse(tiled, s, K);
    for (const Views& v : views)
      expect_same_surfaces(plain.raycast(K, v.pose), tiled.raycast(K, v.pose),
                           std::string(v.name) + "_tile" + std::to_string(tile), v.sees_front);
  }
}

// The block-index window is a cache in front of the hash table: it returns the same pool indices,
// so the march takes the same samples and the maps are bit-identical, whether the window covers
// every block (128), cuts through the model (2: most lookups fall back to the table) or is off.
TEST(TsdfRaycastWindow, SameMapsWithAndWithoutTheWindow) {
  Intrinsics K = test::camera(200, 150, 170.f);
  test::Scene s = scene();
  VolumeParams off = params_with_tile(8);
  off.raycast_window = 0;
  VoxelHashVolume plain(off, Device::CPU);
  fuse(plain, s, K);
  const SE3 views[] = {test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f),
                       test::pose({0.f, 0.f, 2.0f}, 3.14159265f, 0.f), test::pose({0.f, 0.f, 0.f}, 1.2f, 0.f)};
  for (int side : {2, 128}) {
    VolumeParams p = off;
    p.raycast_window = side;
    VoxelHashVolume windowed(p, Device::CPU);
    fuse(windowed, s, K);
    for (int v = 0; v < 4; ++v) {
      RaycastMaps a = plain.raycast(K, views[v]), b = windowed.raycast(K, views[v]);
      auto da = a.depth.to_host(), db = b.depth.to_host();
      auto va = a.vertex.to_host(), vb = b.vertex.to_host();
      int hits = 0;
      for (std::size_t i = 0; i < da.size(); ++i) {
        ASSERT_EQ(da[i], db[i]) << "window " << side << " pixel " << i;
        ASSERT_TRUE(va[i].x == vb[i].x && va[i].y == vb[i].y && va[i].z == vb[i].z)
            << "window " << side << " pixel " << i;
        hits += da[i] > 0.f;
      }
      if (v == 0) {
        EXPECT_GT(hits, static_cast<int>(da.size()) / 4) << "the first view must see the model";
      }
    }
  }
}

// The rays the intervals leave out (tiles with no block) are misses in the plain march too, and
// an empty volume casts no ray at all.
TEST(TsdfRaycastIntervals, EmptyVolumeHitsNothing) {
  Intrinsics K = test::camera(64, 48, 60.f);
  VoxelHashVolume vol(params_with_tile(8), Device::CPU);
  auto depth = vol.raycast(K, SE3::identity()).depth.to_host();
  for (float d : depth) ASSERT_EQ(d, 0.f);
}

// The raycast of vol by the plain march from min_depth through every allocated block, with march
// flags (one word per pool block: kernels::HashAccess::march_flags) or without: no intervals, no
// window.
RaycastMaps plain_march(const VoxelHashVolume& vol, const Intrinsics& K, const SE3& pose,
                        const Buffer<std::int32_t>* march = nullptr) {
  RaycastMaps m;
  detail::resize_maps(m, K, vol.device());
  const kernels::RaycastOutput out{m.depth.view(), m.vertex.view(), m.normal.view(), m.color.view()};
  kernels::HashAccess a = vol.device_view();
  if (march) a.march_flags = march->data();
  with_exec(vol.device(), [&]<class E>(const E& ex) {
    kernels::TsdfRaycast<E>::raycast(ex, a, K, pose, vol.params().min_depth, vol.params().max_depth, out);
  });
  return m;
}

VoxelHashVolume stored_free_space_scene(int tile, const Intrinsics& K) {
  VoxelHashVolume vol(params_with_tile(tile), Device::CPU);
  vol.set_free_space_storage(true);
  fuse(vol, scene(), K);
  return vol;
}

// The march reads the march flags: with every block's at 0 it skips them all and hits nothing;
// with kMarchNear and kMarchCross on every one it skips none and is the plain march, bit for bit.
TEST(TsdfRaycastSurfaceFlags, TheMarchSkipsTheBlocksNotNearASurface) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  VoxelHashVolume vol = stored_free_space_scene(0, K);
  const SE3 view = test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f);
  const std::int64_t pool = vol.stats().block_capacity;
  const auto none = Buffer<std::int32_t>::from_host(std::vector<std::int32_t>(pool, 0), Device::CPU);
  const auto all = Buffer<std::int32_t>::from_host(
      std::vector<std::int32_t>(pool, kernels::kMarchNear | kernels::kMarchCross), Device::CPU);
  for (float d : plain_march(vol, K, view, &none).depth.to_host()) ASSERT_EQ(d, 0.f);
  const auto plain = plain_march(vol, K, view).depth.to_host(),
             flagged = plain_march(vol, K, view, &all).depth.to_host();
  int hits = 0;
  for (std::size_t i = 0; i < plain.size(); ++i) {
    ASSERT_EQ(plain[i], flagged[i]) << i;
    hits += plain[i] > 0.f;
  }
  EXPECT_GT(hits, static_cast<int>(plain.size()) / 4);
}

// With the free space stored, the raycast (surface flags, intervals of the blocks near a surface)
// against the plain march through every stored block, on the sphere, box and wall from the views
// of HitTheSameSurfacesAsThePlainMarch. The flags skip only blocks whose samples read no voxel
// within 0.999 truncation of a surface (kernels::block_march_flags), so both find the same
// surfaces, from different samples: where both hit, within 1 mm (the regula falsi residual of
// differing brackets, as in expect_same_surfaces). Left out: pixels within 2 of a silhouette (a
// jump of over 5 cm in the true depth), where a ray grazes a surface and whether a step lands in
// its thin crossing depends on where the samples fall, in either march. A hit in one and a miss
// in the other elsewhere comes from the model's border (cells partly unobserved, where the
// march's unobserved steps decide alike): at most 0.1 % of the hits.
TEST(TsdfRaycastSurfaceFlags, SameSurfacesAsTheMarchThroughTheFreeSpace) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  const test::Scene s = scene();
  const SE3 views[] = {test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), test::pose({-0.15f, 0.1f, 0.55f}),
                       test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f), test::pose({0.f, 0.f, 2.0f}, 3.14159265f, 0.f)};
  for (int tile : {0, 8}) {  // mark_march_flags, or the flags set by splat_ray_intervals
    VoxelHashVolume vol = stored_free_space_scene(tile, K);
    for (int v = 0; v < 4; ++v) {
      const auto plain = plain_march(vol, K, views[v]).depth.to_host();
      const auto flagged = vol.raycast(K, views[v]).depth.to_host();
      const auto truth = s.render(K, views[v]);
      auto silhouette = [&](int x, int y) {
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int u = x + dx, w = y + dy;
            if (u >= 0 && w >= 0 && u < K.width && w < K.height &&
                std::fabs(truth[static_cast<std::size_t>(w) * K.width + u] -
                          truth[static_cast<std::size_t>(y) * K.width + x]) > 0.05f)
              return true;
          }
        return false;
      };
      int hits = 0, hit_mismatch = 0;
      for (int y = 0; y < K.height; ++y)
        for (int x = 0; x < K.width; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * K.width + x;
          if (silhouette(x, y)) continue;
          if ((plain[i] > 0.f) != (flagged[i] > 0.f)) {
            ++hit_mismatch;
            continue;
          }
          if (plain[i] <= 0.f) continue;
          ++hits;
          EXPECT_NEAR(plain[i], flagged[i], 1e-3f) << "tile " << tile << " view " << v << " pixel " << x << "," << y;
        }
      EXPECT_LE(hit_mismatch, hits / 1000 + 1) << "tile " << tile << " view " << v;
      if (v < 3) {
        EXPECT_GT(hits, static_cast<int>(plain.size()) / 4) << "view " << v << " must see the model";
      }
    }
  }
}

// --- the coarse march: blocks whose samples are all > 0 crossed in one step ----------------------

// Every stored block's flag word is its definition (voxel_flag_bits over its voxels), and the march
// flags computed from the words (block_march_flags) never leave kMarchCross off a block one of
// whose samples can be <= 0: one with an observed voxel <= 0 among the voxels its cells read, the
// 9^3 voxels 8b + {0..8}^3 (counted here from the downloaded voxels, by coordinate). The scene
// (sphere, box, wall) has blocks of the band's free-space side only: those the march crosses whole.
void expect_march_flags_cover_every_crossing(VoxelHashVolume& vol) {
  const auto blocks = vol.download_blocks();
  const float below = 0.999f * vol.params().truncation;
  std::map<std::tuple<int, int, int>, const VoxelHashVolume::HostBlock*> by_coord;
  for (const auto& b : blocks) by_coord[{b.coord.x, b.coord.y, b.coord.z}] = &b;
  auto non_positive_at = [&](int3 g) {  // an observed voxel <= 0 at voxel g
    const int3 b = kernels::block_of_voxel(g);
    const auto it = by_coord.find({b.x, b.y, b.z});
    if (it == by_coord.end()) return false;
    const kernels::Voxel& v = it->second->voxels[kernels::local_index(g)];
    return v.weight > 0.f && v.sdf <= 0.f;
  };
  const kernels::HashAccess a = vol.device_view();  // a CPU volume: the table is host memory
  std::vector<std::int32_t> words(static_cast<std::size_t>(vol.stats().block_capacity), 0);
  for (const auto& b : blocks) {
    std::int32_t expect = 0;
    for (int k = 0; k < kernels::kBlockVoxels; ++k)
      expect |= kernels::voxel_flag_bits(b.voxels[k], kernels::local_coords(k), below);
    ASSERT_EQ(b.flags, expect) << b.coord.x << "," << b.coord.y << "," << b.coord.z;
    words[a.find_block(b.coord)] = b.flags;
  }
  int crossed_whole = 0;
  for (const auto& b : blocks) {
    const std::int32_t m = kernels::block_march_flags(a.table, words.data(), false, b.coord, a.find_block(b.coord));
    bool may_cross = false;
    for (int z = 0; z <= 8 && !may_cross; ++z)
      for (int y = 0; y <= 8 && !may_cross; ++y)
        for (int x = 0; x <= 8 && !may_cross; ++x)
          may_cross = non_positive_at({b.coord.x * 8 + x, b.coord.y * 8 + y, b.coord.z * 8 + z});
    if (may_cross) {
      ASSERT_TRUE(m & kernels::kMarchCross) << b.coord.x << "," << b.coord.y << "," << b.coord.z;
    }
    ASSERT_TRUE(m & kernels::kMarchNear);  // no near test asked: the band-only volume's blocks
    crossed_whole += !(m & kernels::kMarchCross);
  }
  EXPECT_GT(crossed_whole, static_cast<int>(blocks.size()) / 10) << "of " << blocks.size();
  ::testing::Test::RecordProperty("blocks_crossed_whole", std::to_string(crossed_whole));
}

TEST(TsdfRaycastCoarse, MarchFlagsCoverEveryCrossing) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  VoxelHashVolume vol(params_with_tile(8), Device::CPU);
  fuse(vol, scene(), K);
  expect_march_flags_cover_every_crossing(vol);
}

// The raycast (march flags: blocks whose samples are all > 0 crossed in one step, a crossing just
// behind one bracketed from a sample just before its exit) against the fine march through every
// block's samples, band-only volume, the views of HitTheSameSurfacesAsThePlainMarch and tiles of 0
// (mark_march_flags) and 8 (the splat's flags): the same zero crossings of the same trilinear
// field, refined from different brackets, so where both hit within 1 mm (the regula falsi
// residual, as in expect_same_surfaces). Left out, as in SameSurfacesAsTheMarchThroughTheFreeSpace:
// pixels within 2 of a silhouette (a jump of over 5 cm in the true depth), where a ray grazes a
// surface and whether a step lands in its thin crossing depends on where the samples fall.
// Elsewhere a hit in one and a miss in the other: at most 0.1 % of the hits.
TEST(TsdfRaycastCoarse, SameSurfacesAsTheFineMarch) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  const test::Scene s = scene();
  const SE3 views[] = {test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), test::pose({-0.15f, 0.1f, 0.55f}),
                       test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f), test::pose({0.f, 0.f, 2.0f}, 3.14159265f, 0.f)};
  for (int tile : {0, 8}) {
    VoxelHashVolume vol(params_with_tile(tile), Device::CPU);
    fuse(vol, s, K);
    for (int v = 0; v < 4; ++v) {
      const auto fine = plain_march(vol, K, views[v]).depth.to_host();
      const auto coarse = vol.raycast(K, views[v]).depth.to_host();
      const auto truth = s.render(K, views[v]);
      auto silhouette = [&](int x, int y) {
        for (int dy = -2; dy <= 2; ++dy)
          for (int dx = -2; dx <= 2; ++dx) {
            const int u = x + dx, w = y + dy;
            if (u >= 0 && w >= 0 && u < K.width && w < K.height &&
                std::fabs(truth[static_cast<std::size_t>(w) * K.width + u] -
                          truth[static_cast<std::size_t>(y) * K.width + x]) > 0.05f)
              return true;
          }
        return false;
      };
      int hits = 0, hit_mismatch = 0;
      for (int y = 0; y < K.height; ++y)
        for (int x = 0; x < K.width; ++x) {
          const std::size_t i = static_cast<std::size_t>(y) * K.width + x;
          if (silhouette(x, y)) continue;
          if ((fine[i] > 0.f) != (coarse[i] > 0.f)) {
            ++hit_mismatch;
            continue;
          }
          if (fine[i] <= 0.f) continue;
          ++hits;
          EXPECT_NEAR(fine[i], coarse[i], 1e-3f) << "tile " << tile << " view " << v << " pixel " << x << "," << y;
        }
      EXPECT_LE(hit_mismatch, hits / 1000) << "tile " << tile << " view " << v;
      if (v < 3) {
        EXPECT_GT(hits, static_cast<int>(fine.size()) / 4) << "tile " << tile << " view " << v;
      }
    }
  }
}

// The coarse march on CUDA against the CPU, band-only volume: the flag words agree (the voxels
// agree to 1e-5 m, so a sign bit may differ only through a voxel within 1e-5 m of zero, and the
// surface bit through one within 1e-5 m of its threshold: such blocks are left out), and the
// raycasts, whose march flags each backend computes from its words, agree from the views above as in
// TsdfParity.SameBlocksAndValues: depths within 1e-4 m where both hit, a hit on one backend only for at most 0.1 % of
// the pixels (a ray grazing a block edge).
TEST(TsdfRaycastParity, CoarseMarchOnCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  const Intrinsics K = test::camera(200, 150, 170.f);
  const test::Scene s = scene();
  VoxelHashVolume cpu(params_with_tile(8), Device::CPU), gpu(params_with_tile(8), Device::CUDA);
  fuse(cpu, s, K);
  fuse(gpu, s, K);
  const auto a = cpu.download_blocks(), b = gpu.download_blocks();
  ASSERT_NO_FATAL_FAILURE(test::expect_same_blocks(a, b, false));
  const float below = 0.999f * cpu.params().truncation;
  int compared = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    bool borderline = false;
    for (const kernels::Voxel& v : a[i].voxels)
      borderline =
          borderline || (v.weight > 0.f && (std::fabs(v.sdf) <= 1e-5f || std::fabs(std::fabs(v.sdf) - below) <= 1e-5f));
    if (borderline) continue;
    ASSERT_EQ(a[i].flags, b[i].flags) << "block " << i;
    ++compared;
  }
  EXPECT_GT(compared, static_cast<int>(a.size()) / 2);
  const SE3 views[] = {test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), test::pose({-0.15f, 0.1f, 0.55f}),
                       test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f)};
  for (int v = 0; v < 3; ++v) {
    const auto da = cpu.raycast(K, views[v]).depth.to_host(), db = gpu.raycast(K, views[v]).depth.to_host();
    int differ = 0, hits = 0;
    for (std::size_t i = 0; i < da.size(); ++i) {
      if ((da[i] > 0.f) != (db[i] > 0.f)) ++differ;
      else EXPECT_NEAR(da[i], db[i], 1e-4f) << "view " << v << " pixel " << i;
      hits += da[i] > 0.f;
    }
    EXPECT_LE(differ, static_cast<int>(da.size() / 1000)) << "view " << v;
    EXPECT_GT(hits, static_cast<int>(da.size() / 4)) << "view " << v;
  }
}

}  // namespace
}  // namespace seamless
