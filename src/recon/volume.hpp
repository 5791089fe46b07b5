// The TSDF volume interface shared by the voxel-hashed volume (Niessner et al. 2013) and the dense
// grid of KinectFusion (the dissertation's layout, kept for the Figure 5.8 comparison).
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/mesh.hpp"  // Mesh
#include "core/math.hpp"
#include "core/timing.hpp"
#include "recon/scene_particles.hpp"
#include "recon/volume_params.hpp"

namespace seamless {

// Model maps predicted by raycasting (KinectFusion section 3.5): what the tracker aligns to and
// what the renderer shows. Vertices and normals are in world coordinates; depth is camera z.
// A pixel without a hit has depth 0 and zero vertex, normal and colour.
struct RaycastMaps {
  Image<float> depth;
  Image<vec3> vertex;
  Image<vec3> normal;
  Image<uchar3> color;
  // False: the raycast leaves `color` as it was (a geometric tracker never reads it, and its
  // trilinear colour sample is one more TSDF read per hit pixel).
  bool with_color = true;
};

// Per-frame statistics (counts of the last integrate(), totals for the rest).
struct VolumeStats {
  std::int64_t frames = 0;
  std::int64_t allocated_blocks = 0;   // blocks holding voxels now
  std::int64_t block_capacity = 0;     // blocks the pool can hold
  std::int64_t hash_slots = 0;         // 0 for the dense grid
  std::int64_t tombstones = 0;         // deleted hash slots awaiting the next rehash
  double hash_fill = 0.0;              // (live + tombstones) / slots
  std::int64_t inserted = 0;           // blocks allocated by the last frame
  std::int64_t collisions = 0;         // of those, how many did not land in their home slot
  std::int64_t failed_insertions = 0;  // insertions of the last frame that failed even after retries
  std::int64_t retries = 0;            // allocation passes repeated after growing (total)
  std::int64_t visible_blocks = 0;     // blocks fused by the last frame
  std::int64_t removed_blocks = 0;     // blocks freed as empty by the last frame
  std::size_t bytes_per_block = 0;     // voxel payload of one 8^3 block
  std::size_t voxel_bytes = 0;         // allocated_blocks * bytes_per_block
  std::size_t device_bytes = 0;        // everything the volume holds on its device
  std::int64_t host_blocks = 0;        // blocks streamed out to host memory (Niessner section 5)
  std::size_t host_bytes = 0;          // their voxel payload
  std::int64_t streamed_out = 0;       // blocks moved to the host, total
  std::int64_t streamed_in = 0;        // blocks moved back to the device, total
};

class Volume {
 public:
  virtual ~Volume() = default;
  // Fuses one depth frame (metres; rgb may be empty) seen from world_T_camera. The images may live
  // on either device. timer, if given, gets one stage per kernel step.
  virtual void integrate(const Image<float>& depth, const Image<uchar3>& rgb, const Intrinsics& K,
                         const SE3& world_T_camera, StageTimer* timer = nullptr) = 0;
  // Renders the model from any camera into maps (resized to K.width x K.height on the device).
  virtual void raycast(const Intrinsics& K, const SE3& world_T_camera, RaycastMaps& maps,
                       StageTimer* timer = nullptr) = 0;
  RaycastMaps raycast(const Intrinsics& K, const SE3& world_T_camera) {
    RaycastMaps m;
    raycast(K, world_T_camera, m);
    return m;
  }
  // Marching-cubes mesh of everything fused so far, with vertex colours and normals.
  virtual Mesh extract_mesh() = 0;
  // Static scene particles for the physics solver (positions and normals on the volume's device).
  virtual SceneParticles extract_scene_particles(const SceneParticleParams& p) = 0;
  // The SDF on a regular grid (x fastest) at origin + voxel * (x, y, z); unknown points read as
  // +truncation (free space). For the solver's scene_collision: sdf.
  virtual std::vector<float> sample_sdf_grid(vec3 origin, int3 dims, float voxel) = 0;
  // Dynamic pixels (docs/DYNAMIC.md): clears the candidates (1 per pixel of depth, seen
  // from world_T_camera) whose measured point the volume does not show in free space, i.e. not
  // seen through by earlier frames (require_seen_free) or occupied by a surface (otherwise);
  // kernels::DynamicSpace::require_free_space. Both images live on the volume's device.
  virtual void require_free_space(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera,
                                  float min_weight, bool require_seen_free, Image<std::uint8_t>& candidates) = 0;
  virtual VolumeStats stats() = 0;
  virtual Device device() const = 0;
  virtual const VolumeParams& params() const = 0;
  // Free-space carving in later integrate() calls (docs/DYNAMIC.md): voxels more than
  // `metres` in front of the measurement are reset to free space; 0 (the default) turns it off.
  void set_free_space_carving(float metres) { carve_ = metres; }
  // Evidence of free space (docs/DYNAMIC.md): later integrate() calls also store the free
  // space in front of each reading, so that require_free_space can find space seen through. The
  // dense grid stores every voxel anyway; the voxel-hashed volume then allocates the blocks along
  // the rays in front of the readings (kernels::TsdfFusion::allocate_free_space) and keeps every
  // block with an observed voxel. Off (the default): only the truncation band is stored.
  void set_free_space_storage(bool on) { store_free_space_ = on; }

 protected:
  float carve_ = 0.f;
  bool store_free_space_ = false;
};

// Builds the layout named by params.layout ("hash" or "dense") on device d.
std::unique_ptr<Volume> make_volume(const VolumeParams& params, Device d);

namespace detail {
// Ensures maps hold K.width x K.height images on d.
void resize_maps(RaycastMaps& maps, const Intrinsics& K, Device d);
// The image itself when it is on d, else a copy there (held by tmp).
template <class T> const Image<T>& on_device(const Image<T>& im, Device d, Image<T>& tmp) {
  if (im.device() == d || im.width() * im.height() == 0) return im;
  tmp = im.clone(d);
  return tmp;
}
}  // namespace detail

}  // namespace seamless
