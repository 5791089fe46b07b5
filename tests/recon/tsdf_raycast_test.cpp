// Ray-interval raycasting (Niessner et al. 2013, section 4.3) against the plain march from
// min_depth: the same surfaces from the same model, seen from views that put blocks across the
// near plane, partly outside the image, and behind surfaces.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

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

// The raycast of vol by the plain march from min_depth through every allocated block, with near
// (one flag per pool block: kernels::HashAccess::near_surface) or without: no intervals, no window.
RaycastMaps plain_march(const VoxelHashVolume& vol, const Intrinsics& K, const SE3& pose,
                        const Buffer<std::int32_t>* near = nullptr) {
  RaycastMaps m;
  detail::resize_maps(m, K, vol.device());
  const kernels::RaycastOutput out{m.depth.view(), m.vertex.view(), m.normal.view(), m.color.view()};
  kernels::HashAccess a = vol.device_view();
  if (near) a.near_surface = near->data();
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

// The march reads the near-surface flags: with every block's at 0 it skips them all and hits
// nothing; with every one at 1 it skips none and is the plain march, bit for bit.
TEST(TsdfRaycastSurfaceFlags, TheMarchSkipsTheBlocksNotNearASurface) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  VoxelHashVolume vol = stored_free_space_scene(0, K);
  const SE3 view = test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f);
  const std::int64_t pool = vol.stats().block_capacity;
  const auto none = Buffer<std::int32_t>::from_host(std::vector<std::int32_t>(pool, 0), Device::CPU);
  const auto all = Buffer<std::int32_t>::from_host(std::vector<std::int32_t>(pool, 1), Device::CPU);
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
// within 0.999 truncation of a surface (kernels::block_near_surface), so both find the same
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
  for (int tile : {0, 8}) {  // mark_near_surface, or the flags set by splat_ray_intervals
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

// The visible pass lists the live slots (what the volume asks for on CUDA), and the interval pass
// over that list gives what it gives over the whole table: the list holds each live slot once
// (tombstones left out), the visible slots are the same with and without listing, and the
// interval tiles and window entries are the same bit for bit (minima and maxima do not depend on
// the order). The table holds the blocks of the fused scene at a fill of 1/8 with a fifth of them
// erased again, seen from a view inside the model and one looking past it.
void expect_listed_slots_give_the_tables_results(Device dev) {
  const Intrinsics K = test::camera(200, 150, 170.f);
  VoxelHashVolume vol(params_with_tile(8), Device::CPU);
  fuse(vol, scene(), K);
  const kernels::VoxelGeometry geom = vol.device_view().geom;
  const std::vector<int3> blocks = vol.allocated_block_coords();
  ASSERT_GT(blocks.size(), 500u);
  std::int64_t slots = 1;
  while (slots < 8 * static_cast<std::int64_t>(blocks.size())) slots *= 2;
  Buffer<kernels::HashKey> keys(slots, dev);
  const std::int64_t pool = static_cast<std::int64_t>(blocks.size());
  Buffer<std::int32_t> values(slots, dev), free_list(pool, dev), out(pool, dev), live(pool, dev), visible(pool, dev),
      keep(pool, dev), flags(slots, dev), in_order(slots, dev);
  Buffer<kernels::HashCounters> counters(1, dev);
  const kernels::HashTableView t{keys.data(), values.data(), static_cast<std::uint32_t>(slots - 1)};
  std::vector<kernels::HashKey> all, erased;
  for (std::size_t i = 0; i < blocks.size(); ++i) (i % 5 == 2 ? erased : all).push_back(kernels::pack_block(blocks[i]));
  all.insert(all.end(), erased.begin(), erased.end());
  const auto all_d = Buffer<kernels::HashKey>::from_host(all, dev);
  const auto erased_d = Buffer<kernels::HashKey>::from_host(erased, dev);
  const std::int64_t n_live = static_cast<std::int64_t>(all.size() - erased.size());
  const std::int64_t n = with_exec(dev, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_clear(ex, t);
    kernels::VoxelHash<E>::pool_reset(ex, free_list.view(), counters.data());
    kernels::VoxelHash<E>::insert_with_blocks(ex, t, free_list.cview(), counters.data(), all_d.cview(), out.view());
    kernels::VoxelHash<E>::hash_erase(ex, t, erased_d.cview(), out.view(), counters.data());
    return kernels::VoxelHash<E>::hash_live_slots(ex, t, flags.view(), in_order.view());
  });
  ASSERT_EQ(n, n_live);
  std::vector<std::int32_t> want = in_order.to_host();
  want.resize(static_cast<std::size_t>(n));

  const auto depth = Image<float>::from_host(std::vector<float>(K.width * K.height, 1.f), K.width, K.height, dev);
  const auto grid = kernels::TileGrid::covering(K.width, K.height, 8);
  Buffer<std::int32_t> bits(2 * grid.count(), dev), window(16 * 16 * 16, dev);
  const SE3 views[] = {test::pose({0.02f, 0.01f, 0.03f}, 0.03f, -0.02f), test::pose({0.f, 0.f, 0.f}, 0.6f, 0.1f)};
  for (const SE3& view : views) {
    const kernels::FrameInput in{depth.cview(), {}, K, view, 0.1f, 3.f};
    auto visible_of = [&](View<std::int32_t> list) {  // as the volume runs it: counters zeroed first
      with_exec(dev, [&]<class E>(const E& ex) {
        kernels::VoxelHash<E>::reset_frame_counters(ex, counters.data());
        kernels::TsdfFusion<E>::find_visible_blocks(ex, t, counters.data(), in, geom, visible.view(), keep.view(), {},
                                                    nullptr, list);
      });
      std::vector<std::int32_t> v = visible.to_host();
      v.resize(static_cast<std::size_t>(counters.to_host()[0].visible));
      std::sort(v.begin(), v.end());
      return v;
    };
    const auto whole = visible_of({});
    EXPECT_EQ(counters.to_host()[0].listed, 0);
    const auto with_list = visible_of(live.view());
    EXPECT_GT(whole.size(), 100u);
    EXPECT_LT(whole.size(), static_cast<std::size_t>(n_live));  // the view must cull some
    EXPECT_EQ(whole, with_list);
    ASSERT_EQ(counters.to_host()[0].listed, n_live);
    std::vector<std::int32_t> l = live.to_host();
    l.resize(static_cast<std::size_t>(n_live));
    std::sort(l.begin(), l.end());
    EXPECT_EQ(l, want) << "the list holds the live slots, each once";

    // The views look along +z: the window from the camera's block on, 16 blocks deep.
    const kernels::BlockWindow w{window.data(), floor_to_int(geom.to_voxel(view.t) / 8.f) - int3{8, 8, 1}, 16};
    auto splat = [&](kernels::SlotRange r) {
      with_exec(dev, [&]<class E>(const E& ex) {
        const kernels::RayIntervals iv{grid, bits.data()};
        kernels::TsdfRaycast<E>::clear_ray_intervals(ex, iv, w);
        kernels::TsdfRaycast<E>::splat_ray_intervals(ex, t, geom, K, view, 0.1f, 3.f, iv, w, nullptr, nullptr, r);
      });
      return std::make_pair(bits.to_host(), window.to_host());
    };
    const auto [bits_whole, window_whole] = splat({});
    const auto [bits_listed, window_listed] = splat({live.data(), &counters.data()->listed, pool});
    EXPECT_EQ(bits_whole, bits_listed);
    EXPECT_EQ(window_whole, window_listed);
    EXPECT_GT(std::count_if(window_whole.begin(), window_whole.end(), [](std::int32_t b) { return b >= 0; }), 50);
    EXPECT_GT(std::count_if(bits_whole.begin(), bits_whole.end(),
                            [](std::int32_t b) { return b != kernels::kEmptyFar && b != kernels::kEmptyNear; }),
              grid.count());
  }
}

TEST(TsdfRaycastSlots, ListedLiveSlotsGiveTheTablesResults) {
  expect_listed_slots_give_the_tables_results(Device::CPU);
}

TEST(TsdfParity, ListedLiveSlotsGiveTheTablesResultsOnCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  expect_listed_slots_give_the_tables_results(Device::CUDA);
}

}  // namespace
}  // namespace seamless
