#include "recon/scene_particles.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <vector>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/tsdf.hpp"

namespace seamless {

namespace {

// Candidates before thinning: position, normal, score (kernels::scene_particle_emit).
struct Candidates {
  Buffer<vec3> positions, normals;
  Buffer<float> scores;
  std::int64_t count = 0;
};

// Concatenates per-chunk buffers into one of `total` elements on device d.
template <class T> Buffer<T> concat(std::vector<Buffer<T>>& parts, std::int64_t total, Device d) {
  Buffer<T> out(total, d);
  std::int64_t at = 0;
  for (auto& b : parts) {
    memory::copy(out.data() + at, d, b.data(), d, b.bytes());
    at += b.size();
  }
  return out;
}

// The candidates of all blocks, a chunk of blocks at a time (bounds the per-lattice-point scratch).
template <class Acc>
Candidates candidates(Device d, const Acc& a, const Buffer<int3>& blocks, std::int64_t block_count,
                      const SceneParticleParams& p) {
  const int m = kernels::lattice_per_block(a.geom.voxel_size, p.spacing);
  const std::int64_t per_block = static_cast<std::int64_t>(m) * m * m;
  const std::int64_t chunk = std::max<std::int64_t>(1, (std::int64_t(1) << 22) / per_block);
  std::vector<Buffer<vec3>> pos_parts, nrm_parts;
  std::vector<Buffer<float>> score_parts;
  Candidates c;
  for (std::int64_t first = 0; first < block_count; first += chunk) {
    std::int64_t nb = std::min(chunk, block_count - first);
    View<const int3> part{blocks.data() + first, nb};
    Buffer<std::int32_t> offsets(nb * per_block, d);
    std::int64_t n = with_exec(d, [&]<class E>(const E& ex) {
      return kernels::TsdfExtract<E, Acc>::scene_particle_count(ex, a, part, p.spacing, p.interior_depth,
                                                                offsets.view());
    });
    if (n == 0) continue;
    Buffer<vec3> pos(n, d), nrm(n, d);
    Buffer<float> score(n, d);
    with_exec(d, [&]<class E>(const E& ex) {
      kernels::TsdfExtract<E, Acc>::scene_particle_emit(ex, a, part, p.spacing, p.interior_depth, offsets.cview(),
                                                        pos.view(), nrm.view(), score.view());
    });
    c.count += n;
    pos_parts.push_back(std::move(pos)), nrm_parts.push_back(std::move(nrm)), score_parts.push_back(std::move(score));
  }
  c.positions = concat(pos_parts, c.count, d);
  c.normals = concat(nrm_parts, c.count, d);
  c.scores = concat(score_parts, c.count, d);
  return c;
}

// Drops every candidate closer than min_distance to one that outranks it (kernels::scene_particle_thin).
SceneParticles thin(Device d, const Candidates& c, float min_distance) {
  SceneParticles out;
  if (c.count == 0) return out;
  Buffer<std::uint64_t> keys(c.count, d);
  Buffer<std::int32_t> order(c.count, d), keep(c.count, d);
  with_exec(d, [&]<class E>(const E& ex) {
    out.count = kernels::TsdfExtract<E>::scene_particle_thin(ex, c.positions.cview(), c.scores.cview(), min_distance,
                                                             keys.view(), order.view(), keep.view());
  });
  out.positions = Buffer<vec3>(out.count, d);
  out.normals = Buffer<vec3>(out.count, d);
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::TsdfExtract<E>::scene_particle_compact(ex, keep.cview(), out.count, c.positions.cview(), c.normals.cview(),
                                                    out.positions.view(), out.normals.view());
  });
  return out;
}

}  // namespace

template <class Acc>
SceneParticles extract_scene_particles(Device d, const Acc& a, const Buffer<int3>& blocks, std::int64_t block_count,
                                       const SceneParticleParams& p) {
  if (!(p.spacing > 0.f)) throw Error("scene particles: spacing must be positive");
  if (p.interior_depth > a.geom.truncation)
    spdlog::warn(
        "scene particles: interior_depth {} m is deeper than the TSDF truncation {} m; the fill stops at the "
        "truncation (raise volume.truncation to fill deeper)",
        p.interior_depth, a.geom.truncation);
  return thin(d, candidates(d, a, blocks, block_count, p), kSceneParticleMinDistance * p.spacing);
}

template SceneParticles extract_scene_particles<kernels::HashAccess>(Device, const kernels::HashAccess&,
                                                                     const Buffer<int3>&, std::int64_t,
                                                                     const SceneParticleParams&);
template SceneParticles extract_scene_particles<kernels::DenseAccess>(Device, const kernels::DenseAccess&,
                                                                      const Buffer<int3>&, std::int64_t,
                                                                      const SceneParticleParams&);

template <class Acc>
std::vector<float> sample_sdf_grid(Device d, const Acc& a, vec3 origin, int3 dims, float voxel, float unknown) {
  const std::int64_t n = std::int64_t{dims.x} * dims.y * dims.z;
  if (dims.x <= 0 || dims.y <= 0 || dims.z <= 0 || !(voxel > 0.f))
    throw Error("SDF grid: dimensions and voxel size must be positive");
  Buffer<float> out(n, d);
  with_exec(d, [&]<class E>(const E& ex) {
    kernels::TsdfExtract<E, Acc>::sample_sdf_grid(ex, a, origin, dims, voxel, unknown, out.view());
  });
  return out.to_host();
}

template std::vector<float> sample_sdf_grid<kernels::HashAccess>(Device, const kernels::HashAccess&, vec3, int3, float,
                                                                 float);
template std::vector<float> sample_sdf_grid<kernels::DenseAccess>(Device, const kernels::DenseAccess&, vec3, int3,
                                                                  float, float);

}  // namespace seamless
