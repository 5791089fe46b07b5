// The dense TSDF grid of KinectFusion (Newcombe et al. 2011; the dissertation's layout): every
// voxel of a fixed cube is stored and fused every frame. Kept behind the Volume interface as the
// comparator of the dissertation's Figure 5.8 (time per frame against voxel count). The grid is
// stored brick-major (8^3 bricks), which lets it share every kernel with the hashed volume
// through kernels::DenseAccess; the work per frame is still one thread per voxel of the cube.
#pragma once
#include "kernels/recon/voxel_hash.hpp"
#include "recon/volume.hpp"

namespace seamless {

class DenseVolume final : public Volume {
 public:
  // params.dense_resolution voxels per side (rounded up to a multiple of 8) of size
  // params.voxel_size, min corner at params.dense_origin.
  DenseVolume(const VolumeParams& params, Device d);

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

  kernels::DenseAccess device_view() const { return {voxels_.data(), colors_.data(), blocks_per_side_, geom_}; }

 private:
  VolumeParams params_;
  Device device_;
  kernels::VoxelGeometry geom_;
  int blocks_per_side_;
  Buffer<kernels::Voxel> voxels_;
  Buffer<uchar3> colors_;  // the colour of voxels_[i] at colors_[i]
  Buffer<int3> block_coords_;
  std::int64_t frames_ = 0;
};

}  // namespace seamless
