// The voxel-hashed TSDF volume (Niessner, Zollhoefer, Izadi, Stamminger 2013). Design, memory and
// failure handling: docs/RECONSTRUCTION.md.
#pragma once
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
  Mesh extract_mesh() override;
  SceneParticles extract_scene_particles(const SceneParticleParams& p) override;
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
  };
  std::vector<HostBlock> download_blocks() const;
  // Block coordinates of the allocated blocks, sorted like download_blocks().
  std::vector<int3> allocated_block_coords() const;
  // Slots of the live blocks on the device (count returned); the list used by extraction.
  std::int64_t live_slots(Buffer<std::int32_t>& slots) const;
  // Block coordinates of the allocated blocks on the device (count returned).
  std::int64_t live_block_coords(Buffer<int3>& coords) const;

 private:
  kernels::HashTableView table() const;
  // Blocks with no observed voxel closer to a surface than this (metres) are freed as empty.
  float keep_below() const { return 0.999f * geom_.truncation; }
  kernels::HashCounters read_counters() const;
  void allocate_and_list(const kernels::FrameInput& in, StageTimer* timer);
  void handle_failures(const kernels::HashCounters& c);
  void maybe_rehash();
  void rehash(std::int64_t slots);
  void grow_pool(std::int64_t blocks);

  VolumeParams params_;
  Device device_;
  kernels::VoxelGeometry geom_;
  Buffer<kernels::HashKey> keys_;
  Buffer<std::int32_t> values_;
  Buffer<kernels::Voxel> voxels_;
  Buffer<std::int32_t> free_list_;
  Buffer<kernels::HashCounters> counters_;
  Buffer<std::int32_t> visible_;
  Buffer<std::int32_t> keep_;             // per visible block: 1 = has a voxel near a surface
  Buffer<std::int32_t> intervals_;        // ray-interval tiles (kernels::RayIntervals)
  mutable Buffer<std::int32_t> scratch_;  // one int per slot for scans
  kernels::HashCounters last_{};          // counters as read at the end of the last frame
  std::int64_t frames_ = 0, retries_ = 0, failed_ = 0;
};

}  // namespace seamless
