#include "recon/voxel_hash_volume.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <tuple>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/dynamic.hpp"
#include "kernels/recon/tsdf.hpp"
#include "recon/marching_cubes.hpp"

namespace seamless {

using kernels::HashCounters;
using kernels::kBlockVoxels;

namespace {
constexpr int kMaxProbe = 128;  // linear probing at <= 50% fill rarely probes past 20 slots
// Allocation passes after growing, per frame. Each growth at least doubles the pool or the table,
// so this bound is never the one that stops growth: the pool's 2^30 blocks (grow_pool) come first.
constexpr int kMaxGrowths = 40;
constexpr std::int64_t kMaxSlots = std::int64_t{1} << 30;

// Blocks of a pool of `pool` handed out, by the counters' free-list top.
std::int64_t blocks_in_use(std::int64_t pool, const HashCounters& c) { return pool - std::max(c.free_top, 0); }

// Keys in the table that hold no block: the distinct blocks a frame could not get from a full pool
// (they stay in the table with value -1; the pool_failures counter counts every attempt, many per
// block). A host copy of the table: only for the warning of a pool that may not grow.
std::int64_t keys_without_block(const Buffer<kernels::HashKey>& keys, const Buffer<std::int32_t>& values) {
  const std::vector<kernels::HashKey> k = keys.to_host();
  const std::vector<std::int32_t> v = values.to_host();
  std::int64_t n = 0;
  for (std::size_t i = 0; i < k.size() && i < v.size(); ++i) n += kernels::is_live_key(k[i]) && v[i] < 0;
  return n;
}

std::int64_t next_pow2(std::int64_t n) {
  std::int64_t p = 1;
  while (p < n) p <<= 1;
  return p;
}

// Runs fn inside a timer stage when there is a timer.
template <class F> void staged(StageTimer* timer, const char* stage, F&& fn) {
  if (!timer) return fn();
  StageScope s(*timer, stage);
  fn();
}
}  // namespace

VoxelHashVolume::VoxelHashVolume(const VolumeParams& p, Device d)
    : params_(p), device_(d), growing_start_(p.capacity == 0 && d == Device::CPU && p.grow_when_full) {
  p.validate();
  params_.capacity = p.start_capacity(d == Device::CUDA);
  geom_ = {{0.f, 0.f, 0.f}, p.voxel_size, p.truncation};
  const std::int64_t slots = next_pow2(std::max<std::int64_t>(p.hash_buckets, 1024));
  keys_ = Buffer<kernels::HashKey>(slots, d);
  values_ = Buffer<std::int32_t>(slots, d);
  scratch_ = Buffer<std::int32_t>(slots, d);
  const std::int64_t capacity = params_.capacity;
  // The pool's arrays on the host are pages the kernel zero-fills as the scan first writes them,
  // and grow without a copy (grow_pool).
  voxels_ = Buffer<kernels::Voxel>::zeros(capacity * kBlockVoxels, d);
  colors_ = Buffer<uchar3>::zeros(capacity * kBlockVoxels, d);
  free_list_ = Buffer<std::int32_t>(capacity, d);
  visible_ = Buffer<std::int32_t>(capacity, d);
  keep_ = Buffer<std::int32_t>(capacity, d);
  surface_ = Buffer<std::int32_t>::zeros(capacity, d);
  counters_ = Buffer<HashCounters>(1, d);
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_clear(ex, table());
    kernels::VoxelHash<E>::pool_reset(ex, free_list_.view(), counters_.data());
  });
  last_ = read_counters();
}

std::uint64_t VoxelHashVolume::pool_size() const { return static_cast<std::uint64_t>(free_list_.size()); }

kernels::HashTableView VoxelHashVolume::table() const {
  return {keys_.data(), values_.data(), static_cast<std::uint32_t>(keys_.size() - 1), kMaxProbe};
}

kernels::HashAccess VoxelHashVolume::device_view() const { return {table(), voxels_.data(), colors_.data(), geom_}; }

HashCounters VoxelHashVolume::read_counters() const { return counters_.to_host()[0]; }

void VoxelHashVolume::integrate(const Image<float>& depth, const Image<uchar3>& rgb, const Intrinsics& K,
                                const SE3& world_T_camera, StageTimer* timer) {
  if (rgb.width() * rgb.height() != 0 && (rgb.width() != depth.width() || rgb.height() != depth.height()))
    throw Error("integrate: the colour image (" + std::to_string(rgb.width()) + "x" + std::to_string(rgb.height()) +
                ") must match the depth image (" + std::to_string(depth.width()) + "x" +
                std::to_string(depth.height()) + "); register colour to depth first");
  Image<float> dtmp;
  Image<uchar3> ctmp;
  const Image<float>& dep = detail::on_device(depth, device_, dtmp);
  const Image<uchar3>& col = detail::on_device(rgb, device_, ctmp);
  kernels::FrameInput in{
      dep.cview(),      col.width() ? col.cview() : View2D<const uchar3>{}, K, world_T_camera, params_.min_depth,
      params_.max_depth};
  in.carve = carve_;
  if (params_.stream_radius > 0.f) staged(timer, "stream", [&] { maybe_stream(K, world_T_camera.t); });
  maybe_rehash(last_);
  allocate_and_list(in, timer);
  known_window_ = {};  // fusion may free blocks (remove_unkept_blocks)
  const std::int64_t n = last_.visible;
  // Fusion flags the visible blocks that keep a voxel near a surface, so removing the others
  // needs no second pass over their voxels (one thread per voxel there, not per block).
  const View<std::int32_t> keep = params_.remove_empty_blocks ? keep_.view() : View<std::int32_t>{};
  with_exec(device_, [&]<class E>(const E& ex) {
    staged(timer, "fuse", [&] {
      // On the CPU the visible blocks are fused in pool order (kernels/recon/tsdf.hpp,
      // sort_visible_by_block: docs/PERFORMANCE.md measures it); CUDA fuses them as listed, each
      // block's voxels in one pass of coalesced loads, where the order of the blocks matters little.
      if (device_ == Device::CPU)
        kernels::TsdfFusion<E>::sort_visible_by_block(ex, table(), visible_.view(), n, scratch_.view(),
                                                      static_cast<int>(std::bit_width(pool_size())));
      kernels::TsdfFusion<E>::fuse_hash_blocks(ex, table(), visible_.cview(), n, voxels_.data(),
                                               params_.integrate_color ? colors_.data() : nullptr, in, geom_,
                                               params_.max_weight, keep, keep_below(), surface_flags());
    });
    if (params_.remove_empty_blocks)
      staged(timer, "remove_empty", [&] {
        kernels::TsdfFusion<E>::remove_unkept_blocks(ex, table(), visible_.cview(), n, keep_.cview(), voxels_.data(),
                                                     colors_.data(), free_list_.view(), counters_.data());
      });
  });
  ++frames_;
}

// Allocation and the visible list, with the frame's single read of the counters. A pass with
// failed insertions is repeated after growing what ran out (insertion is idempotent).
void VoxelHashVolume::allocate_and_list(const kernels::FrameInput& in, StageTimer* timer) {
  kernels::DepthTiles tiles;  // empty: every block in the frustum is listed
  if (params_.occlusion_tile > 0) {
    const auto grid = kernels::TileGrid::covering(in.depth.width, in.depth.height, params_.occlusion_tile);
    depth_tiles_.reserve_discard(grid.count(), device_);
    tiles = {grid, depth_tiles_.data()};
  }
  const std::int64_t pool_before = free_list_.size(), slots_before = keys_.size();
  for (int attempt = 0;; ++attempt) {
    with_exec(device_, [&]<class E>(const E& ex) {
      kernels::VoxelHash<E>::reset_frame_counters(ex, counters_.data());
      staged(timer, "allocate", [&] {
        if (tiles.zmax) kernels::TsdfFusion<E>::clear_depth_tiles(ex, tiles);
        kernels::TsdfFusion<E>::allocate_blocks(ex, table(), free_list_.cview(), counters_.data(), in, geom_, tiles,
                                                known_window_);
        if (store_free_space_)
          kernels::TsdfFusion<E>::allocate_free_space(ex, table(), free_list_.cview(), counters_.data(), in, geom_);
      });
      staged(timer, "visible", [&] {
        // On CUDA the pass also lists the live slots, which the raycast's interval pass (the only
        // pass that takes the list) then visits instead of the whole table (kernels::SlotRange says
        // why). The CPU skips an empty slot in a few cycles, where appending to one list would cost
        // its threads more than it saves.
        View<std::int32_t> live;
        if (device_ == Device::CUDA && params_.raycast_tile > 0) {
          live_.reserve_discard(static_cast<std::int64_t>(pool_size()), device_);
          live = live_.view();
        }
        kernels::TsdfFusion<E>::find_visible_blocks(ex, table(), counters_.data(), in, geom_, visible_.view(),
                                                    keep_.view(), tiles, surface_.data(), live);
        listed_ = live.data != nullptr;
      });
    });
    last_ = read_counters();
    failed_ = last_.probe_failures + last_.pool_failures;
    if (failed_ == 0 || !params_.grow_when_full) break;
    // Grow as often as this frame needs: a frame that is only partly fused is a hole in the model
    // that tracking then fails against (a pool of 64 blocks doubled 4 times, then
    // dropped the rest of the frame and every later frame was lost).
    if (attempt == kMaxGrowths)
      throw Error("voxel hashing: " + std::to_string(failed_) + " block insertions still fail in frame " +
                  std::to_string(frames_) + " after growing " + std::to_string(kMaxGrowths) +
                  " times; raise volume.voxel_size or lower volume.max_depth");
    handle_failures(last_);
    ++retries_;
  }
  if (free_list_.size() != pool_before && growing_start_)  // the CPU's small start grows by design
    spdlog::debug("voxel hashing: grew the block pool from {} to {} blocks in frame {}", pool_before, free_list_.size(),
                  frames_);
  else if (free_list_.size() != pool_before)
    spdlog::warn(
        "voxel hashing: block pool full in frame {}; grew it from {} to {} blocks (set volume.capacity: {} to "
        "avoid this pause)",
        frames_, pool_before, free_list_.size(), free_list_.size());
  if (keys_.size() != slots_before)
    spdlog::warn(
        "voxel hashing: hash table too crowded in frame {}; rehashed it from {} into {} slots (set "
        "volume.hash_buckets: {} to avoid this pause)",
        frames_, slots_before, keys_.size(), keys_.size());
  if (failed_ > 0) {  // volume.grow_when_full is off
    // The advice from this frame's numbers: the blocks it holds plus the distinct blocks it could
    // not get, a quarter more for the next frames' new surface; the table is sized like growing
    // does it (twice the slots), and at least four slots a block (the load growing keeps).
    const std::int64_t pool = free_list_.size();
    const std::int64_t needed =
        blocks_in_use(pool, last_) + (last_.pool_failures > 0 ? keys_without_block(keys_, values_) : 0);
    std::string advice;
    if (last_.pool_failures > 0)
      advice += "volume.capacity >= " + std::to_string(needed + needed / 4) + " (this frame needed about " +
                std::to_string(needed) + " blocks)";
    if (last_.probe_failures > 0)
      advice += std::string(advice.empty() ? "" : " and ") + "volume.hash_buckets >= " +
                std::to_string(std::max<std::int64_t>(2 * static_cast<std::int64_t>(keys_.size()), 4 * needed));
    spdlog::warn(
        "voxel hashing: {} block insertion attempts failed in frame {} ({} found no hash slot within {} probes, "
        "{} found the pool of {} blocks full); that part of the frame is not fused. Set {}, or "
        "volume.grow_when_full: true",
        failed_, frames_, last_.probe_failures, kMaxProbe, last_.pool_failures, pool, advice);
  }
}

kernels::SlotRange VoxelHashVolume::listed() const {
  if (!listed_) return {};
  return {live_.data(), &counters_.data()->listed, static_cast<std::int64_t>(pool_size())};
}

void VoxelHashVolume::handle_failures(const HashCounters& c) {
  // Logged once per frame by allocate_and_list, with the sizes reached.
  if (c.probe_failures > 0) {
    // Insertion never reuses a tombstone, so a block that is freed and allocated again frame after
    // frame (a surface seen, then seen through) leaves one more tombstone before its key each time:
    // after max_probe such frames its insertion fails in a table that is nearly empty. Clearing the
    // tombstones in place is then the remedy; doubling is for a table that is really full (a
    // 10,000-frame run doubled 11 times with 65,536 blocks and overflowed 32-bit slot indices).
    const std::int64_t slots = keys_.size();
    const std::int64_t live = blocks_in_use(free_list_.size(), c);
    // (No tombstones left, as after an in-place rehash, and still failing: a real cluster; grow.)
    const bool crowded = 4 * live > slots || c.tombstones == 0;
    spdlog::debug(
        "voxel hashing: {} insertions found no slot in a table of {} slots ({} blocks, {} tombstones); "
        "rehashing into {} slots",
        c.probe_failures, slots, live, c.tombstones, crowded ? 2 * slots : slots);
    rehash(crowded ? 2 * slots : slots);
  }
  if (c.pool_failures > 0) {
    std::int64_t cap = free_list_.size();
    spdlog::debug("voxel hashing: block pool full ({} blocks, {} insertion attempts failed); growing it to {} blocks",
                  cap, c.pool_failures, 2 * cap);
    grow_pool(2 * cap);
  }
}

// Between frames: clears tombstones and keeps the fill at or below one half, where linear probing
// stays short (Knuth: expected probes (1 + 1/(1-a)^2)/2 = 2.5 for an unsuccessful search at a = 1/2).
// extra: keys about to be inserted besides allocation (streaming in).
void VoxelHashVolume::maybe_rehash(const HashCounters& c, std::int64_t extra) {
  const std::int64_t slots = keys_.size();
  const std::int64_t live = blocks_in_use(free_list_.size(), c) + extra;
  if (2 * (live + c.tombstones) <= slots) return;
  if (4 * live > slots && params_.grow_when_full) return rehash(next_pow2(4 * live));
  if (4 * live > slots)
    spdlog::warn(
        "voxel hashing: {} of {} hash slots hold blocks; insertions may start failing (set "
        "volume.hash_buckets: {} or volume.grow_when_full: true)",
        live, slots, 2 * slots);
  rehash(slots);
}

std::int64_t VoxelHashVolume::live_slots(Buffer<std::int32_t>& slots) const {
  if (slots.size() < free_list_.size() || slots.device() != device_)
    slots = Buffer<std::int32_t>(free_list_.size(), device_);
  return with_exec(device_, [&]<class E>(const E& ex) {
    return kernels::VoxelHash<E>::hash_live_slots(ex, table(), scratch_.view(), slots.view());
  });
}

void VoxelHashVolume::rehash(std::int64_t new_slots) {
  known_window_ = {};
  listed_ = false;  // the keys move to other slots
  // Slots are indexed by 32-bit integers in the kernels (HashTable::mask, block slot lists).
  if (new_slots > kMaxSlots)
    throw Error("voxel hashing: the hash table cannot grow beyond " + std::to_string(kMaxSlots) +
                " slots; raise volume.voxel_size or lower volume.max_depth");
  Buffer<std::int32_t> slots;
  const std::int64_t n = live_slots(slots);
  Buffer<kernels::HashKey> keys(n, device_);
  Buffer<std::int32_t> values(n, device_), slot_out(n, device_), result(n, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_gather(ex, table(), View<const std::int32_t>{slots.data(), n}, keys.view(),
                                       values.view());
  });
  keys_ = Buffer<kernels::HashKey>(new_slots, device_);
  values_ = Buffer<std::int32_t>(new_slots, device_);
  scratch_ = Buffer<std::int32_t>(new_slots, device_);
  HashCounters c = read_counters();
  c.tombstones = 0;
  c.probe_failures = 0;
  counters_.copy_from_host(&c, 1);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_clear(ex, table());
    kernels::VoxelHash<E>::hash_insert(ex, table(), keys.cview(), values.cview(), slot_out.view(), result.view(),
                                       counters_.data());
  });
  HashCounters after = read_counters();
  if (after.probe_failures > 0)
    throw Error("voxel hashing: rehashing " + std::to_string(n) + " blocks into " + std::to_string(new_slots) +
                " slots failed; set volume.hash_buckets to at least " + std::to_string(4 * n));
  after.inserted = c.inserted;
  after.collisions = c.collisions;
  counters_.copy_from_host(&after, 1);
  last_.tombstones = 0;
}

void VoxelHashVolume::grow_pool(std::int64_t blocks) {
  listed_ = false;  // the list's bound is the pool's size
  const std::int64_t old = free_list_.size();
  if (blocks > (1ll << 30))
    throw Error(
        "voxel hashing: the block pool cannot grow beyond 2^30 blocks; raise volume.voxel_size or lower "
        "volume.max_depth");
  voxels_.grow_zeroed(blocks * kBlockVoxels);
  colors_.grow_zeroed(blocks * kBlockVoxels);
  surface_.grow_zeroed(blocks);
  Buffer<std::int32_t> free_list(blocks, device_);
  free_list.copy_from(free_list_);
  free_list_ = std::move(free_list);
  visible_ = Buffer<std::int32_t>(blocks, device_);
  keep_ = Buffer<std::int32_t>(blocks, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::pool_append(ex, free_list_.view(), counters_.data(), static_cast<std::int32_t>(old),
                                       static_cast<std::int32_t>(blocks - old));
  });
  params_.capacity = blocks;
}

std::int64_t VoxelHashVolume::remove_empty_blocks() {
  known_window_ = {};
  listed_ = false;  // its count is reset below
  Buffer<std::int32_t> slots;
  const std::int64_t n = live_slots(slots);
  Buffer<std::int32_t> keep(n, device_);
  keep.zero();
  const View<const std::int32_t> listed{slots.data(), n};
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::reset_frame_counters(ex, counters_.data());
    kernels::TsdfFusion<E>::mark_kept_blocks(ex, table(), listed, n, voxels_.data(), keep.view(), keep_below(),
                                             geom_.truncation);
    kernels::TsdfFusion<E>::remove_unkept_blocks(ex, table(), listed, n, keep.cview(), voxels_.data(), colors_.data(),
                                                 free_list_.view(), counters_.data());
  });
  last_ = read_counters();
  return last_.removed;
}

std::vector<int3> VoxelHashVolume::allocated_block_coords() const {
  Buffer<std::int32_t> slots;
  const std::int64_t n = live_slots(slots);
  Buffer<kernels::HashKey> keys(n, device_);
  Buffer<std::int32_t> values(n, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_gather(ex, table(), View<const std::int32_t>{slots.data(), n}, keys.view(),
                                       values.view());
  });
  std::vector<int3> out;
  for (kernels::HashKey k : keys.to_host()) out.push_back(kernels::unpack_block(k));
  std::sort(out.begin(), out.end(), [](int3 a, int3 b) { return std::tie(a.x, a.y, a.z) < std::tie(b.x, b.y, b.z); });
  return out;
}

std::vector<VoxelHashVolume::HostBlock> VoxelHashVolume::download_blocks() const {
  Buffer<std::int32_t> slots;
  const std::int64_t n = live_slots(slots);
  Buffer<kernels::HashKey> keys(n, device_);
  Buffer<std::int32_t> values(n, device_);
  Buffer<kernels::Voxel> vox(n * kBlockVoxels, device_);
  Buffer<uchar3> col(n * kBlockVoxels, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_gather(ex, table(), View<const std::int32_t>{slots.data(), n}, keys.view(),
                                       values.view());
    kernels::VoxelHash<E>::gather_blocks(ex, voxels_.data(), colors_.data(), values.cview(), vox.view(), col.view());
  });
  std::vector<kernels::HashKey> hk = keys.to_host();
  std::vector<kernels::Voxel> hv = vox.to_host();
  std::vector<uchar3> hc = col.to_host();
  const std::vector<std::int32_t> hb = values.to_host(), flags = surface_.to_host();
  std::vector<HostBlock> out(static_cast<std::size_t>(n));
  for (std::int64_t i = 0; i < n; ++i) {
    out[i].coord = kernels::unpack_block(hk[i]);
    out[i].voxels.assign(hv.begin() + i * kBlockVoxels, hv.begin() + (i + 1) * kBlockVoxels);
    out[i].colors.assign(hc.begin() + i * kBlockVoxels, hc.begin() + (i + 1) * kBlockVoxels);
    out[i].surface = flags[hb[i]] != 0;
  }
  std::sort(out.begin(), out.end(), [](const HostBlock& a, const HostBlock& b) {
    return std::tie(a.coord.x, a.coord.y, a.coord.z) < std::tie(b.coord.x, b.coord.y, b.coord.z);
  });
  return out;
}

// The camera's block sits at the middle of the window's back face (along the view direction's
// dominant axis), so the window covers the frustum up to `side` blocks deep and side / 2 blocks
// either way across; the table answers for blocks outside it.
kernels::BlockWindow VoxelHashVolume::raycast_window(const SE3& world_T_camera) {
  const int side = params_.raycast_window;
  if (side <= 0) return {};
  window_.reserve_discard(static_cast<std::int64_t>(side) * side * side, device_);
  const vec3 cam = geom_.to_voxel(world_T_camera.t) / 8.f;  // block units
  const vec3 fwd = world_T_camera.rotate(vec3{0.f, 0.f, 1.f});
  const float f[3] = {fwd.x, fwd.y, fwd.z}, c[3] = {cam.x, cam.y, cam.z};
  int axis = 0;
  for (int k = 1; k < 3; ++k)
    if (std::fabs(f[k]) > std::fabs(f[axis])) axis = k;
  int o[3];
  for (int k = 0; k < 3; ++k) o[k] = static_cast<int>(std::floor(c[k])) - side / 2;  // centred on the camera
  o[axis] = static_cast<int>(std::floor(c[axis])) - (f[axis] > 0.f ? 1 : side - 2);  // one block behind it
  return {window_.data(), int3{o[0], o[1], o[2]}, side};
}

void VoxelHashVolume::raycast(const Intrinsics& K, const SE3& world_T_camera, RaycastMaps& maps, StageTimer* timer) {
  detail::resize_maps(maps, K, device_);
  kernels::RaycastOutput out{maps.depth.view(), maps.vertex.view(), maps.normal.view(),
                             maps.with_color ? maps.color.view() : View2D<uchar3>{}};
  kernels::RayIntervals iv;  // empty: every ray marches from min_depth
  if (params_.raycast_tile > 0) {
    const auto grid = kernels::TileGrid::covering(K.width, K.height, params_.raycast_tile);
    intervals_.reserve_discard(2 * grid.count(), device_);
    iv = {grid, intervals_.data()};
  }
  // With free space stored, the march skips the blocks not near a surface as it skips unallocated
  // ones (kernels::block_near_surface); the band-only volume has freed those blocks already.
  kernels::HashAccess view = device_view();
  const std::int32_t* surface = nullptr;
  if (store_free_space_) {
    near_.reserve_discard(static_cast<std::int64_t>(pool_size()), device_);
    surface = surface_.data(), view.near_surface = near_.data();
  }
  with_exec(device_, [&]<class E>(const E& ex) {
    staged(timer, "raycast", [&] {
      const kernels::BlockWindow w = raycast_window(world_T_camera);
      known_window_ = {};                     // until the window is filled below
      if (iv.bits)                            // one pass over the slots splats the intervals and fills the window
        staged(timer, "raycast_splat", [&] {  // part of "raycast"
          kernels::TsdfRaycast<E>::clear_ray_intervals(ex, iv, w);
          kernels::TsdfRaycast<E>::splat_ray_intervals(ex, table(), geom_, K, world_T_camera, params_.min_depth,
                                                       params_.max_depth, iv, w, surface, near_.data(), listed());
        });
      else if (surface) kernels::TsdfRaycast<E>::mark_near_surface(ex, table(), surface, near_.data());
      if (!w.index) {
        kernels::TsdfRaycast<E, kernels::HashAccess>::raycast(ex, view, K, world_T_camera, params_.min_depth,
                                                              params_.max_depth, out, iv);
        return;
      }
      if (!iv.bits)
        staged(timer, "raycast_window",
               [&] { kernels::TsdfRaycast<E>::fill_block_window(ex, table(), w); });  // part of "raycast"
      known_window_ = w;  // every block of the table inside it
      kernels::TsdfRaycast<E, kernels::WindowedHashAccess>::raycast(
          ex, kernels::WindowedHashAccess{view, w}, K, world_T_camera, params_.min_depth, params_.max_depth, out, iv);
    });
  });
}

std::int64_t VoxelHashVolume::live_block_coords(Buffer<int3>& coords) const {
  Buffer<std::int32_t> slots;
  const std::int64_t n = live_slots(slots);
  coords = Buffer<int3>(n, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::TsdfExtract<E>::slot_block_coords(ex, table(), View<const std::int32_t>{slots.data(), n}, coords.view());
  });
  return n;
}

Mesh VoxelHashVolume::extract_mesh(bool progress) {
  Buffer<int3> coords;
  const std::int64_t n = live_block_coords(coords);
  Buffer<kernels::HashKey> keys(n, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::TsdfExtract<E>::sort_blocks(ex, View<int3>{coords.data(), n}, keys.view());
  });
  return marching_cubes(device_, device_view(), coords, n, progress);
}

SceneParticles VoxelHashVolume::extract_scene_particles(const SceneParticleParams& p) {
  Buffer<int3> coords;
  const std::int64_t n = live_block_coords(coords);
  return seamless::extract_scene_particles(device_, device_view(), coords, n, p);
}

std::vector<float> VoxelHashVolume::sample_sdf_grid(vec3 origin, int3 dims, float voxel) {
  return seamless::sample_sdf_grid(device_, device_view(), origin, dims, voxel, params_.truncation);
}

void VoxelHashVolume::require_free_space(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera,
                                         float min_weight, bool require_seen_free, Image<std::uint8_t>& candidates) {
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::DynamicSpace<E, kernels::HashAccess>::require_free_space(
        ex, device_view(), depth.cview(), K, world_T_camera, min_weight, require_seen_free, candidates.view());
  });
}

VolumeStats VoxelHashVolume::stats() {
  HashCounters c = read_counters();
  VolumeStats s;
  s.frames = frames_;
  s.block_capacity = free_list_.size();
  s.allocated_blocks = s.block_capacity - std::max(c.free_top, 0);
  s.hash_slots = keys_.size();
  s.tombstones = c.tombstones;
  s.hash_fill = double(s.allocated_blocks + s.tombstones) / double(s.hash_slots);
  s.inserted = last_.inserted;
  s.collisions = last_.collisions;
  s.failed_insertions = failed_;
  s.retries = retries_;
  s.visible_blocks = last_.visible;
  s.removed_blocks = c.removed;
  s.bytes_per_block = (sizeof(kernels::Voxel) + sizeof(uchar3)) * kBlockVoxels;
  s.voxel_bytes = s.bytes_per_block * static_cast<std::size_t>(s.allocated_blocks);
  s.device_bytes = keys_.bytes() + values_.bytes() + scratch_.bytes() + voxels_.bytes() + colors_.bytes() +
                   free_list_.bytes() + visible_.bytes() + keep_.bytes() + surface_.bytes() + near_.bytes() +
                   intervals_.bytes() + depth_tiles_.bytes() + counters_.bytes();
  s.host_blocks = host_count_;
  s.host_bytes = s.bytes_per_block * static_cast<std::size_t>(host_count_);
  s.streamed_out = streamed_out_;
  s.streamed_in = streamed_in_;
  return s;
}

}  // namespace seamless
