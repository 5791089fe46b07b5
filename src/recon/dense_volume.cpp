#include "recon/dense_volume.hpp"

#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/dynamic.hpp"
#include "kernels/recon/tsdf.hpp"
#include "recon/marching_cubes.hpp"

namespace seamless {

DenseVolume::DenseVolume(const VolumeParams& p, Device d) : params_(p), device_(d) {
  p.validate();
  blocks_per_side_ = (p.dense_resolution + kernels::kBlockSide - 1) / kernels::kBlockSide;
  params_.dense_resolution = blocks_per_side_ * kernels::kBlockSide;
  geom_ = {p.dense_origin, p.voxel_size, p.truncation};
  const std::int64_t n = blocks_per_side_;
  voxels_ = Buffer<kernels::Voxel>(n * n * n * kernels::kBlockVoxels, d);
  voxels_.zero();
  colors_ = Buffer<uchar3>(n * n * n * kernels::kBlockVoxels, d);
  colors_.zero();
  std::vector<int3> coords;
  coords.reserve(static_cast<std::size_t>(n * n * n));
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) coords.push_back({x, y, z});  // index = x + n (y + n z), as DenseAccess
  block_coords_ = Buffer<int3>::from_host(coords, d);
}

void DenseVolume::integrate(const Image<float>& depth, const Image<uchar3>& rgb, const Intrinsics& K,
                            const SE3& world_T_camera, StageTimer* timer) {
  Image<float> dtmp;
  Image<uchar3> ctmp;
  const Image<float>& dep = detail::on_device(depth, device_, dtmp);
  const Image<uchar3>& col = detail::on_device(rgb, device_, ctmp);
  kernels::FrameInput in{
      dep.cview(),      col.width() ? col.cview() : View2D<const uchar3>{}, K, world_T_camera, params_.min_depth,
      params_.max_depth};
  in.carve = carve_;
  if (timer) timer->begin("fuse");
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::TsdfFusion<E>::fuse_dense_blocks(ex, device_view(), in, params_.max_weight, params_.integrate_color);
  });
  if (timer) timer->end("fuse");
  ++frames_;
}

void DenseVolume::raycast(const Intrinsics& K, const SE3& world_T_camera, RaycastMaps& maps, StageTimer* timer) {
  detail::resize_maps(maps, K, device_);
  kernels::RaycastOutput out{maps.depth.view(), maps.vertex.view(), maps.normal.view(),
                             maps.with_color ? maps.color.view() : View2D<uchar3>{}};
  if (timer) timer->begin("raycast");
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::TsdfRaycast<E, kernels::DenseAccess>::raycast(ex, device_view(), K, world_T_camera, params_.min_depth,
                                                           params_.max_depth, out);
  });
  if (timer) timer->end("raycast");
}

Mesh DenseVolume::extract_mesh(bool progress) {
  return marching_cubes(device_, device_view(), block_coords_, block_coords_.size(), progress);
}

SceneParticles DenseVolume::extract_scene_particles(const SceneParticleParams& p) {
  return seamless::extract_scene_particles(device_, device_view(), block_coords_, block_coords_.size(), p);
}

std::vector<float> DenseVolume::sample_sdf_grid(vec3 origin, int3 dims, float voxel) {
  return seamless::sample_sdf_grid(device_, device_view(), origin, dims, voxel, params_.truncation);
}

void DenseVolume::require_free_space(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera,
                                     float min_weight, bool require_seen_free, Image<std::uint8_t>& candidates) {
  with_exec(device_, [&]<class E>(const E& ex) {
    kernels::DynamicSpace<E, kernels::DenseAccess>::require_free_space(
        ex, device_view(), depth.cview(), K, world_T_camera, min_weight, require_seen_free, candidates.view());
  });
}

VolumeStats DenseVolume::stats() {
  VolumeStats s;
  s.frames = frames_;
  s.allocated_blocks = s.block_capacity = block_coords_.size();
  s.visible_blocks = s.allocated_blocks;
  s.bytes_per_block = (sizeof(kernels::Voxel) + sizeof(uchar3)) * kernels::kBlockVoxels;
  s.voxel_bytes = voxels_.bytes() + colors_.bytes();
  s.device_bytes = voxels_.bytes() + colors_.bytes() + block_coords_.bytes();
  return s;
}

}  // namespace seamless
