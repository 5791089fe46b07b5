// Volume section (`volume:`): the TSDF volume layout and fusion parameters.
// Voxel hashing after Niessner et al. 2013; the dense grid is the KinectFusion comparator.
#pragma once
#include <cmath>
#include <cstdint>
#include <string>

#include "core/error.hpp"
#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

enum class VolumeLayout { hash, dense };
inline std::span<const EnumName<VolumeLayout>> enum_names(VolumeLayout) {
  static constexpr EnumName<VolumeLayout> names[] = {{VolumeLayout::hash, "hash"}, {VolumeLayout::dense, "dense"}};
  return names;
}

struct VolumeParams {
  VolumeLayout layout = VolumeLayout::hash;
  float voxel_size = 0.005f;  // metres
  float truncation = 0.02f;   // metres (4 voxels at the default size)
  float max_weight = 100.f;   // running-average weight cap (lets the model adapt)
  std::int64_t hash_buckets = 1 << 20;
  // 8^3-voxel blocks the pool starts with; 0: by the device (start_capacity).
  std::int64_t capacity = 0;
  int dense_resolution = 512;              // voxels per side of the dense cube
  vec3 dense_origin{-1.28f, -1.28f, 0.f};  // world position of the dense cube's min corner
  float min_depth = 0.3f;                  // Kinect v1 minimum range, metres
  float max_depth = 4.0f;                  // beyond this depth is too noisy to fuse
  bool integrate_color = true;
  bool remove_empty_blocks = true;
  bool grow_when_full = true;  // double the hash table / block pool instead of dropping blocks
  int raycast_tile = 8;        // pixels per side of a ray-interval tile (Niessner 4.3); 0: none
  int raycast_window = 128;    // blocks per side of the raycast's block-index window; 0: none
  int occlusion_tile = 8;      // pixels per side of the depth tiles that cull occluded blocks; 0: none
  float stream_radius = 0.f;   // blocks beyond this distance from the camera go to host memory; 0: off
  float stream_step = 0.25f;   // camera travel (metres) between two streaming passes

  // The pool a voxel-hashed volume starts with. capacity 0 chooses by the device: on CUDA 2^18
  // blocks (896 MiB of 4-byte voxels and 3-byte colours), reserved up front because growing there stops the frame
  // and briefly holds the old and the new pool on the GPU; on the CPU 4096 blocks (14 MiB), grown
  // by doubling as the scan needs them (grow_when_full), so a small scan does not reserve and zero
  // 896 MiB of host memory. Without grow_when_full the CPU starts large as well.
  static constexpr std::int64_t kDeviceCapacity = std::int64_t{1} << 18;
  static constexpr std::int64_t kHostStartCapacity = 4096;
  std::int64_t start_capacity(bool on_cuda) const {
    if (capacity > 0) return capacity;
    return on_cuda || !grow_when_full ? kDeviceCapacity : kHostStartCapacity;
  }

  // Rules across keys, checked when a config is loaded (Experiment::validate) and by the volumes'
  // constructors (for code that builds a volume without a config).
  void validate() const {
    std::vector<std::string> problems;
    check(problems);
    if (!problems.empty()) throw ConfigError(problems.front());
  }
  // The same, every problem appended to `problems` (config loading lists them all at once).
  void check(std::vector<std::string>& problems) const {
    if (truncation < 2.f * voxel_size)
      problems.push_back("volume.truncation (" + std::to_string(truncation) + " m) must be at least two voxels (2 * " +
                         "volume.voxel_size = " + std::to_string(2.f * voxel_size) +
                         " m): the truncation band must reach the voxels on both sides of the surface");
    if (capacity > (std::int64_t{1} << 30)) problems.push_back("volume.capacity must be below 2^30 blocks");
    if (max_weight != std::floor(max_weight))
      problems.push_back("volume.max_weight (" + std::to_string(max_weight) +
                         ") must be a whole number: a voxel stores its weight as a 16-bit count of fused frames");
  }

  template <class V> void visit(V& v) {
    v("layout", layout, "volume layout: voxel hashing or dense grid");
    v("voxel_size", voxel_size, "voxel edge length, metres", Range{0.0005, 1.0});
    v("truncation", truncation, "TSDF truncation distance, metres", Range{0.001, 2.0});
    // At most 65535 (kernels::kMaxVoxelWeight): the voxel's weight is a 16-bit count (voxel_hash.hpp).
    v("max_weight", max_weight,
      "maximum fusion weight per voxel, a whole count of frames (16 bits; the running average stops following "
      "an observation closer than (max_weight + 1) / 2 steps of truncation / 32767 to the stored distance)",
      Range{1.0, 65535.0});
    v("hash_buckets", hash_buckets, "hash table buckets (hash layout)", Range{1024, 1e9});
    v("capacity", capacity,
      "voxel blocks the pool starts with (hash layout); 0: by the device, 262144 (896 MiB) on CUDA, 4096 (14 MiB) "
      "on the CPU growing as needed (grow_when_full)",
      Range{0, 1e9});
    v("dense_resolution", dense_resolution, "voxels per side (dense layout)", Range{8, 2048});
    v("dense_origin", dense_origin, "min corner of the dense cube in world coordinates, metres");
    v("min_depth", min_depth, "ignore depth closer than this, metres", Range{0.0, 100.0});
    v("max_depth", max_depth, "ignore depth farther than this, metres", Range{0.01, 100.0});
    v("integrate_color", integrate_color, "fuse RGB colour into the voxels");
    v("remove_empty_blocks", remove_empty_blocks, "free blocks whose voxels all became empty");
    v("grow_when_full", grow_when_full,
      "when the hash table or block pool runs out, grow it (and retry) instead of dropping blocks with a warning");
    v("raycast_tile", raycast_tile,
      "hash layout: rays march only over the depth range of the blocks projecting onto their tile of this many "
      "pixels per side (Niessner 2013, section 4.3); 0 marches every ray from min_depth",
      Range{0, 256});
    v("raycast_window", raycast_window,
      "hash layout: before a raycast, the blocks in a cube of this many blocks per side in front of the camera "
      "are indexed densely, so rays find them with one load instead of hash probes (4 bytes per entry: 128 "
      "gives 8 MiB); blocks outside it are still found through the table; 0: off",
      Range{0, 512});
    v("occlusion_tile", occlusion_tile,
      "hash layout: a frame skips the blocks it cannot change: those whose nearest point lies more than the "
      "truncation behind the farthest depth reading of every tile of this many pixels per side that they project "
      "onto (or onto tiles without a reading); 0 fuses every block in the view frustum",
      Range{0, 256});
    v("stream_radius", stream_radius,
      "hash layout: blocks whose centre is farther than this from the camera are moved to host memory and brought "
      "back when the camera returns (Niessner 2013, section 5), metres; 0 keeps everything on the device. Must "
      "exceed the farthest point a frame can touch plus stream_step (checked; about max_depth * 1.26 + 0.4 for a "
      "Kinect)",
      Range{0.0, 1e4});
    v("stream_step", stream_step, "camera travel between two streaming passes, metres", Range{0.01, 100.0});
  }
};

}  // namespace seamless
