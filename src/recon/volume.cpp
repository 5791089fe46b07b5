#include "recon/volume.hpp"

#include "core/error.hpp"
#include "recon/dense_volume.hpp"
#include "recon/voxel_hash_volume.hpp"

namespace seamless {

std::unique_ptr<Volume> make_volume(const VolumeParams& params, Device d) {
  if (params.layout == VolumeLayout::hash) return std::make_unique<VoxelHashVolume>(params, d);
  if (params.layout == VolumeLayout::dense) return std::make_unique<DenseVolume>(params, d);
  throw Error("volume.layout '" + std::string(enum_name(params.layout)) + "' is not available (use hash or dense)");
}

namespace detail {
void resize_maps(RaycastMaps& maps, const Intrinsics& K, Device d) {
  if (maps.depth.width() == K.width && maps.depth.height() == K.height && maps.depth.device() == d) return;
  maps.depth = Image<float>(K.width, K.height, d);
  maps.vertex = Image<vec3>(K.width, K.height, d);
  maps.normal = Image<vec3>(K.width, K.height, d);
  maps.color = Image<uchar3>(K.width, K.height, d);
}
}  // namespace detail

}  // namespace seamless
