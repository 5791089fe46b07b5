// Static scene particles for the physics solver, taken from the fused TSDF's hash blocks.
#pragma once
#include <cstdint>
#include <vector>

#include "core/buffer.hpp"
#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

struct SceneParticleParams {
  float spacing = 0.04f;       // the solver's particle diameter (dissertation: 4 m / 100)
  float interior_depth = 0.f;  // also fill the solid this deep below the surface (<= truncation)

  template <class V> void visit(V& v) {
    v("spacing", spacing, "lattice spacing of the scene particles, metres (the particle diameter)", Range{0.001, 1.0});
    v("interior_depth", interior_depth, "fill the solid interior this deep below the surface, metres", Range{0.0, 2.0});
  }
};

// Surface particles ON the fused surface (zeros of the TSDF on the lattice lines spacing * Z^2
// along the axis the surface faces: about one per spacing^2 of surface, at any height between
// lattice planes), plus, with interior_depth > 0, the lattice points of the solid from spacing/2
// down to interior_depth below it. No two are closer than kSceneParticleMinDistance spacings.
// Normals are the unit TSDF gradient. Both buffers live on the volume's device.
// (kernels/recon/tsdf_extract.inl explains the choice; docs/RECONSTRUCTION.md.)
// Below half a spacing a second particle adds nothing a solver particle (diameter = spacing)
// could feel as a separate contact; the thinning drops the lower-ranked of such pairs.
constexpr float kSceneParticleMinDistance = 0.5f;

struct SceneParticles {
  Buffer<vec3> positions;
  Buffer<vec3> normals;
  std::int64_t count = 0;
};

// Extracts the particles of the given blocks (device block coordinates) through accessor a
// (kernels::HashAccess or kernels::DenseAccess).
template <class Acc>
SceneParticles extract_scene_particles(Device d, const Acc& a, const Buffer<int3>& blocks, std::int64_t block_count,
                                       const SceneParticleParams& p);

// Samples accessor a's SDF on a grid (Volume::sample_sdf_grid); unknown points read `unknown`.
template <class Acc>
std::vector<float> sample_sdf_grid(Device d, const Acc& a, vec3 origin, int3 dims, float voxel, float unknown);

}  // namespace seamless
