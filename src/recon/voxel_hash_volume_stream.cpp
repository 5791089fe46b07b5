// Streaming of voxel blocks between the device and host memory as the camera moves (Niessner,
// Zollhoefer, Izadi, Stamminger 2013, section 5). Design: docs/RECONSTRUCTION.md.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/buffer.hpp"
#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/tsdf.hpp"
#include "recon/voxel_hash_volume.hpp"

namespace seamless {

using kernels::HashCounters;
using kernels::HashKey;
using kernels::kBlockVoxels;
using kernels::Voxel;

namespace {

// Ray length per metre of camera depth at the farthest image corner: a frame touches points up
// to this factor times their depth away from the camera.
float corner_factor(const Intrinsics& K) {
  const float ax = std::max(K.cx + 0.5f, K.width - 0.5f - K.cx) / K.fx;
  const float ay = std::max(K.cy + 0.5f, K.height - 0.5f - K.cy) / K.fy;
  return std::sqrt(1.f + ax * ax + ay * ay);
}

}  // namespace

// A frame allocates and fuses only voxels with camera depth <= max_depth + truncation; the blocks
// that find_visible_blocks lists (and may free) have a corner of their box there, so their centres lie
// within (max_depth + truncation) * corner_factor + one block diagonal of the camera. Passes run
// every stream_step of travel, so a radius beyond that plus stream_step keeps every block a frame
// can touch on the device, and fusion with streaming equals fusion without.
void VoxelHashVolume::maybe_stream(const Intrinsics& K, const vec3& camera_position) {
  const float block_diagonal = kernels::kBlockSide * std::sqrt(3.f) * params_.voxel_size;
  const float reach = (params_.max_depth + params_.truncation) * corner_factor(K) + block_diagonal;
  const float need = reach + params_.stream_step;
  if (params_.stream_radius < need)
    throw ConfigError("volume.stream_radius (" + std::to_string(params_.stream_radius) +
                      " m) is too small: a frame of this camera touches blocks up to " + std::to_string(reach) +
                      " m away (max_depth + truncation at the image corner, plus a block), and the camera moves up to "
                      "volume.stream_step = " +
                      std::to_string(params_.stream_step) + " m between passes; set volume.stream_radius to at least " +
                      std::to_string(need) + " m");
  if (streamed_ && length(camera_position - stream_pos_) < params_.stream_step) return;
  stream(camera_position);
}

void VoxelHashVolume::stream(const vec3& camera_position) {
  stream_out(camera_position);
  std::vector<HashKey> keys;
  std::vector<Voxel> voxels;
  std::vector<uchar3> colors;
  take_from_host(camera_position, false, keys, voxels, colors);
  upload(keys, voxels, colors);
  stream_pos_ = camera_position;
  streamed_ = true;
  const kernels::HashCounters c = read_counters();
  last_.free_top = c.free_top;  // for the next maybe_rehash
  last_.tombstones = c.tombstones;
}

void VoxelHashVolume::stream_in_all() {
  std::vector<HashKey> keys;
  std::vector<Voxel> voxels;
  std::vector<uchar3> colors;
  take_from_host({0.f, 0.f, 0.f}, true, keys, voxels, colors);
  upload(keys, voxels, colors);
  const kernels::HashCounters c = read_counters();
  last_.free_top = c.free_top;
  last_.tombstones = c.tombstones;
}

// The same test as kernels::hash_slots_beyond, in voxel units.
bool VoxelHashVolume::beyond_radius(HashKey key, const vec3& camera_position) const {
  const int3 b = kernels::unpack_block(key);
  const vec3 c{b.x * 8.f + 3.5f, b.y * 8.f + 3.5f, b.z * 8.f + 3.5f};
  const float r = params_.stream_radius / geom_.voxel_size;
  return length2(c - geom_.to_voxel(camera_position)) > r * r;
}

// Gathers the blocks beyond the radius into a staging buffer, copies it to the host, and frees
// them on the device (key tombstoned, block zeroed and pushed on the free list) in one step, so a
// block is never on both sides.
void VoxelHashVolume::stream_out(const vec3& camera_position) {
  known_window_ = {};  // blocks leave the table
  Buffer<std::int32_t> slots(free_list_.size(), device_);
  const float radius = params_.stream_radius / geom_.voxel_size;
  const std::int64_t n = with_exec(device_, [&]<class E>(const E& ex) {
    return kernels::VoxelHash<E>::hash_slots_beyond(ex, table(), geom_.to_voxel(camera_position), radius,
                                                    scratch_.view(), slots.view());
  });
  if (n == 0) return;
  const View<const std::int32_t> listed{slots.data(), n};
  Buffer<HashKey> keys(n, device_);
  Buffer<std::int32_t> blocks(n, device_);
  Buffer<Voxel> staging(n * kBlockVoxels, device_);
  Buffer<uchar3> staging_colors(n * kBlockVoxels, device_);
  memory::fill_zero(keep_.data(), device_, sizeof(std::int32_t) * static_cast<std::size_t>(n));
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::hash_gather(ex, table(), listed, keys.view(), blocks.view());
    kernels::VoxelHash<E>::gather_blocks(ex, voxels_.data(), colors_.data(), blocks.cview(), staging.view(),
                                         staging_colors.view());
    kernels::TsdfFusion<E>::remove_unkept_blocks(ex, table(), listed, n, View<const std::int32_t>{keep_.data(), n},
                                                 voxels_.data(), colors_.data(), free_list_.view(), counters_.data());
  });
  const std::vector<HashKey> hk = keys.to_host();
  const std::vector<Voxel> hv = staging.to_host();
  const std::vector<uchar3> hc = staging_colors.to_host();
  put_on_host(hk.data(), hv.data(), hc.data(), n);
  streamed_out_ += n;
}

void VoxelHashVolume::put_on_host(const HashKey* keys, const Voxel* voxels, const uchar3* colors, std::int64_t n) {
  for (std::int64_t i = 0; i < n; ++i) {
    const int3 b = kernels::unpack_block(keys[i]);
    const HashKey chunk = kernels::pack_block({b.x >> kChunkShift, b.y >> kChunkShift, b.z >> kChunkShift});
    HostChunk& c = host_[chunk];
    c.keys.push_back(keys[i]);
    c.voxels.insert(c.voxels.end(), voxels + i * kBlockVoxels, voxels + (i + 1) * kBlockVoxels);
    c.colors.insert(c.colors.end(), colors + i * kBlockVoxels, colors + (i + 1) * kBlockVoxels);
  }
  host_count_ += n;
}

// Moves the stored blocks within the radius (or all) out of the host store into keys / voxels / colors.
// Whole chunks farther than the radius are passed over without looking at their blocks.
void VoxelHashVolume::take_from_host(const vec3& camera_position, bool all, std::vector<HashKey>& keys,
                                     std::vector<Voxel>& voxels, std::vector<uchar3>& colors) {
  const float chunk_m = static_cast<float>(kernels::kBlockSide << kChunkShift) * geom_.voxel_size;
  const float chunk_reach = params_.stream_radius + chunk_m * std::sqrt(3.f);  // radius + chunk diagonal
  for (auto it = host_.begin(); it != host_.end();) {
    HostChunk& c = it->second;
    const int3 cc = kernels::unpack_block(it->first);
    const vec3 centre =
        geom_.to_world(vec3{cc.x + 0.5f, cc.y + 0.5f, cc.z + 0.5f} * float(kernels::kBlockSide << kChunkShift));
    if (!all && length(centre - camera_position) > chunk_reach) {
      ++it;
      continue;
    }
    std::size_t kept = 0;
    for (std::size_t i = 0; i < c.keys.size(); ++i) {
      const auto at = static_cast<std::ptrdiff_t>(i * kBlockVoxels),
                 to = static_cast<std::ptrdiff_t>(kept * kBlockVoxels);
      const auto src = c.voxels.begin() + at;
      const auto src_colors = c.colors.begin() + at;
      if (!all && beyond_radius(c.keys[i], camera_position)) {  // stays: compact in place
        std::copy(src, src + kBlockVoxels, c.voxels.begin() + to);
        std::copy(src_colors, src_colors + kBlockVoxels, c.colors.begin() + to);
        c.keys[kept++] = c.keys[i];
        continue;
      }
      keys.push_back(c.keys[i]);
      voxels.insert(voxels.end(), src, src + kBlockVoxels);
      colors.insert(colors.end(), src_colors, src_colors + kBlockVoxels);
    }
    host_count_ -= static_cast<std::int64_t>(c.keys.size() - kept);
    c.keys.resize(kept);
    c.voxels.resize(kept * kBlockVoxels);
    c.colors.resize(kept * kBlockVoxels);
    it = kept == 0 ? host_.erase(it) : std::next(it);
  }
}

// Inserts the blocks with fresh pool blocks and copies their voxels in. The pool and table are
// grown first when allowed; what still does not fit goes back to the host store, with a warning.
void VoxelHashVolume::upload(std::vector<HashKey>& keys, std::vector<Voxel>& voxels, std::vector<uchar3>& colors) {
  std::int64_t n = static_cast<std::int64_t>(keys.size());
  if (n == 0) return;
  listed_ = false;  // keys go into slots the list does not hold
  HashCounters c = read_counters();
  const std::int64_t free_blocks = std::max(c.free_top, 0);
  if (free_blocks < n && params_.grow_when_full) {
    std::int64_t cap = free_list_.size();
    while (cap - (free_list_.size() - free_blocks) < n) cap *= 2;
    spdlog::warn(
        "voxel hashing: streaming {} blocks back needs a pool of {} blocks (set volume.capacity: {} to avoid "
        "this pause)",
        n, cap, cap);
    grow_pool(cap);
    c = read_counters();
  }
  const std::int64_t fit = std::min<std::int64_t>(n, std::max(c.free_top, 0));
  maybe_rehash(c, fit);
  Buffer<HashKey> dkeys = Buffer<HashKey>::from_host(keys, device_);
  Buffer<Voxel> dvox = Buffer<Voxel>::from_host(voxels, device_);
  Buffer<uchar3> dcol = Buffer<uchar3>::from_host(colors, device_);
  Buffer<std::int32_t> blocks(fit, device_);
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::VoxelHash<E>::reset_frame_counters(ex, counters_.data());
    kernels::VoxelHash<E>::insert_with_blocks(ex, table(), free_list_.cview(), counters_.data(),
                                              View<const HashKey>{dkeys.data(), fit}, blocks.view());
    kernels::VoxelHash<E>::scatter_blocks(ex, voxels_.data(), colors_.data(), blocks.cview(), dvox.cview(),
                                          dcol.cview());
    kernels::TsdfFusion<E>::mark_surface_blocks(ex, blocks.cview(), voxels_.data(), surface_flags(), geom_.truncation);
  });
  const std::vector<std::int32_t> got = blocks.to_host();
  const HashCounters after = read_counters();
  std::vector<HashKey> back_keys;
  std::vector<Voxel> back_vox;
  std::vector<uchar3> back_col;
  for (std::int64_t i = 0; i < n; ++i) {
    if (i < fit && got[i] >= 0) continue;
    back_keys.push_back(keys[i]);
    back_vox.insert(back_vox.end(), voxels.begin() + i * kBlockVoxels, voxels.begin() + (i + 1) * kBlockVoxels);
    back_col.insert(back_col.end(), colors.begin() + i * kBlockVoxels, colors.begin() + (i + 1) * kBlockVoxels);
  }
  const std::int64_t failed_in = static_cast<std::int64_t>(back_keys.size()) - (n - fit);
  if (failed_in > after.probe_failures + after.pool_failures)
    throw Error("voxel hashing: a streamed-in block was also on the device (" +
                std::to_string(failed_in - after.probe_failures - after.pool_failures) +
                " blocks); the streaming invariant is broken: raise volume.stream_radius");
  put_on_host(back_keys.data(), back_vox.data(), back_col.data(), static_cast<std::int64_t>(back_keys.size()));
  streamed_in_ += n - static_cast<std::int64_t>(back_keys.size());
  if (!back_keys.empty())
    spdlog::warn(
        "voxel hashing: {} streamed blocks did not fit on the device and stay in host memory (set "
        "volume.capacity >= {} and volume.hash_buckets >= {}, or volume.grow_when_full: true)",
        back_keys.size(), 2 * free_list_.size(), 2 * keys_.size());
}

}  // namespace seamless
