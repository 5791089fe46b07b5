// The voxel-hashed TSDF volume (Niessner, Zollhoefer, Izadi, Stamminger 2013). Design, memory and
// failure handling: docs/RECONSTRUCTION.md.
#pragma once
#include <limits>
#include <unordered_map>
#include <utility>
#include <vector>

#include "kernels/recon/tsdf.hpp"
#include "kernels/recon/voxel_hash.hpp"
#include "recon/volume.hpp"

namespace seamless {

class VoxelHashVolume final : public Volume {
 public:
  VoxelHashVolume(const VolumeParams& params, Device d);

  // Per frame (Niessner section 4): allocate the blocks in the truncation band, list the visible
  // blocks, fuse, free the blocks left empty. One device-to-host read of the counters per frame;
  // a failed insertion is retried after growing the table or pool between passes, and counted.
  void integrate(const Image<float>& depth, const Image<uchar3>& rgb, const Intrinsics& K, const SE3& world_T_camera,
                 StageTimer* timer = nullptr) override;
  void raycast(const Intrinsics& K, const SE3& world_T_camera, RaycastMaps& maps, StageTimer* timer = nullptr) override;
  using Volume::raycast;
  Mesh extract_mesh(bool progress) override;
  using Volume::extract_mesh;
  SceneParticles extract_scene_particles(const SceneParticleParams& p) override;
  std::vector<float> sample_sdf_grid(vec3 origin, int3 dims, float voxel) override;
  void require_free_space(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera, float min_weight,
                          bool require_seen_free, Image<std::uint8_t>& candidates) override;
  VolumeStats stats() override;
  Device device() const override { return device_; }
  const VolumeParams& params() const override { return params_; }

  // The device view physics kernels use to look voxels up (kernels::sample_sdf etc.). Valid until
  // the next integrate() (which may grow or rehash the table).
  kernels::HashAccess device_view() const;
  // Frees every allocated block with no voxel near a surface (integrate() does this for the
  // visible blocks when params.remove_empty_blocks is set). Returns how many were freed.
  std::int64_t remove_empty_blocks();
  // Host copy of every allocated block, sorted by block coordinate (x, then y, then z): the unit of
  // streaming to host memory, and what the tests inspect.
  struct HostBlock {
    int3 coord;
    std::vector<kernels::Voxel> voxels;  // 512, x fastest
    std::vector<uchar3> colors;          // 512, the colour of voxels[k] at colors[k]
    bool surface = false;                // its surface flag (kernels::SurfaceFlags)
  };
  std::vector<HostBlock> download_blocks() const;
  // Block coordinates of the allocated blocks, sorted like download_blocks().
  std::vector<int3> allocated_block_coords() const;
  // Slots of the live blocks on the device (count returned); the list used by extraction.
  std::int64_t live_slots(Buffer<std::int32_t>& slots) const;
  // Block coordinates of the allocated blocks on the device (count returned).
  std::int64_t live_block_coords(Buffer<int3>& coords) const;

  // Streaming to host memory (Niessner section 5; design in docs/RECONSTRUCTION.md). With
  // params.stream_radius > 0, integrate() runs a pass whenever the camera has moved stream_step
  // since the last one. A pass moves every block whose centre is farther than stream_radius from
  // camera_position into the host store, then brings every stored block within it back. A block
  // is never on both sides. The accessors above (download, mesh, particles, raycast) see only the
  // blocks on the device: call stream_in_all() first for the whole model.
  void stream(const vec3& camera_position);
  // Brings every stored block back to the device, growing the pool if allowed (else what does not
  // fit stays on the host, with a warning).
  void stream_in_all();
  std::int64_t host_block_count() const { return host_count_; }

 private:
  kernels::HashTableView table() const;
  // The block-index window for a raycast from world_T_camera (index nullptr when off).
  kernels::BlockWindow raycast_window(const SE3& world_T_camera);
  // Blocks with no observed voxel closer to a surface than this (metres) are freed as empty; with
  // free space stored, no observed block is (its +truncation voxels are the evidence kept).
  float keep_below() const { return store_free_space_ ? std::numeric_limits<float>::max() : surface_below(); }
  // A voxel closer to a surface than this (metres) sets its block's surface flag (kernels::SurfaceFlags).
  float surface_below() const { return 0.999f * geom_.truncation; }
  kernels::SurfaceFlags surface_flags() const { return {surface_.data(), surface_below()}; }
  std::uint64_t pool_size() const;  // blocks in the pool: every block index is below it
  kernels::HashCounters read_counters() const;
  void allocate_and_list(const kernels::FrameInput& in, StageTimer* timer);
  kernels::SlotRange listed() const;  // the frame's list of live slots while it holds (listed_), else empty
  void handle_failures(const kernels::HashCounters& c);
  void maybe_rehash(const kernels::HashCounters& c, std::int64_t extra = 0);
  void rehash(std::int64_t slots);
  void grow_pool(std::int64_t blocks);

  // Host store of streamed-out blocks, by chunk of kChunkBlocks^3 blocks (Niessner's chunk grid).
  struct HostChunk {
    std::vector<kernels::HashKey> keys;
    std::vector<kernels::Voxel> voxels;  // 512 per key
    std::vector<uchar3> colors;          // the colour of voxels[k] at colors[k]
  };
  static constexpr int kChunkShift = 3;  // chunks of 8^3 blocks (32 cm at 5 mm voxels)
  void maybe_stream(const Intrinsics& K, const vec3& camera_position);
  void stream_out(const vec3& camera_position);
  void take_from_host(const vec3& camera_position, bool all, std::vector<kernels::HashKey>& keys,
                      std::vector<kernels::Voxel>& voxels, std::vector<uchar3>& colors);
  void put_on_host(const kernels::HashKey* keys, const kernels::Voxel* voxels, const uchar3* colors, std::int64_t n);
  void upload(std::vector<kernels::HashKey>& keys, std::vector<kernels::Voxel>& voxels, std::vector<uchar3>& colors);
  bool beyond_radius(kernels::HashKey key, const vec3& camera_position) const;

  VolumeParams params_;
  Device device_;
  kernels::VoxelGeometry geom_;
  Buffer<kernels::HashKey> keys_;
  Buffer<std::int32_t> values_;
  Buffer<kernels::Voxel> voxels_;
  Buffer<uchar3> colors_;  // the colour of voxels_[i] at colors_[i]
  Buffer<std::int32_t> free_list_;
  Buffer<kernels::HashCounters> counters_;
  Buffer<std::int32_t> visible_;
  Buffer<std::int32_t> keep_;         // per visible block: 1 = has a voxel near a surface
  Buffer<std::int32_t> surface_;      // per pool block: its surface flag (kernels::SurfaceFlags)
  Buffer<std::int32_t> near_;         // per pool block, per raycast: kernels::block_near_surface
  Buffer<std::int32_t> intervals_;    // ray-interval tiles (kernels::RayIntervals)
  Buffer<std::int32_t> depth_tiles_;  // the frame's farthest reading per tile (kernels::DepthTiles)
  Buffer<std::int32_t> window_;       // the raycast's block-index window (kernels::BlockWindow)
  // The last raycast's window while it still holds every block in it (no block freed since), for
  // the next frame's allocation to skip the table's probes; empty otherwise.
  kernels::BlockWindow known_window_{};
  // The frame's list of live slots (find_visible_blocks, CUDA only) while it still holds every live
  // block: no key inserted or moved since (freed ones may stay on it: the passes check each key).
  Buffer<std::int32_t> live_;
  bool listed_ = false;
  mutable Buffer<std::int32_t> scratch_;  // one int per slot for scans
  kernels::HashCounters last_{};          // counters as read at the end of the last frame
  std::int64_t frames_ = 0, retries_ = 0, failed_ = 0;
  std::unordered_map<kernels::HashKey, HostChunk> host_;
  std::int64_t host_count_ = 0, streamed_out_ = 0, streamed_in_ = 0;
  vec3 stream_pos_{0.f, 0.f, 0.f};
  bool streamed_ = false;  // a pass has run (stream_pos_ is set)
  // The pool started small on purpose (volume.capacity 0 on the CPU): growing it is no warning.
  bool growing_start_ = false;
};

}  // namespace seamless
