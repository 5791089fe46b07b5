// Marching cubes over voxel blocks (host side of kernels/recon/tsdf.hpp mesh_count / mesh_edges / mesh_vertices).
#pragma once
#include <cstdint>
#include <vector>

#include "core/buffer.hpp"
#include "recon/volume.hpp"

namespace seamless {

// The triangle table, 256 rows of kernels::kMcRow edge indices (-1 ended), generated rather than
// typed in: for each corner configuration the iso-line on every cube face is found (an ambiguous
// face separates its two inside corners, the same rule from both cubes sharing the face, so the
// mesh is watertight), the face segments are chained into loops and each loop is fanned into
// triangles wound counter-clockwise seen from outside (positive TSDF).
const std::vector<std::int8_t>& marching_cubes_table();

// Meshes the cells of the given blocks (block coordinates on device d) of a volume seen through
// accessor a (kernels::HashAccess or kernels::DenseAccess). Vertices on the same voxel edge are
// merged, so the mesh is indexed and shared across block seams. progress: report the passes
// (core/progress) when there is more than one.
template <class Acc>
Mesh marching_cubes(Device d, const Acc& a, const Buffer<int3>& blocks, std::int64_t block_count,
                    bool progress = false);

}  // namespace seamless
