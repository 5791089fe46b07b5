// The CPU's fusion of a block layer on 8 SIMD lanes (defined in tsdf_fusion_simd.cpp, compiled for AVX2
// where simd::cpu_simd() finds it at run time). Never seen by nvcc.
//
// A layer (the 64 voxels of a block at one z) is fused a row at a time: the 8 voxels along x at one (y, z), 8
// consecutive voxels in the pool, one a lane, each computed with fuse_voxel's expressions in fuse_voxel's order (no FMA
// contraction: simd.hpp), so the fused values are bit-identical to the scalar loop's (tests compare
// both). The scalar loop's chain transform -> projection -> depth read -> average, one voxel after
// the other, is taken once for 8 voxels (docs/PERFORMANCE.md, "The CPU's fusion on SIMD lanes").
#pragma once
#if !defined(__CUDACC__)
#include "core/cpu_simd.hpp"
#include "kernels/recon/tsdf.hpp"

namespace seamless::kernels {

// What every block of a frame's fusion reads (fuse_hash_blocks' arguments).
struct FuseRowFrame {
  FrameInput in;
  SE3 camera_T_world;
  VoxelGeometry geom;
  float max_weight = 0.f;
  float keep_below = 0.f;     // used when keep is set
  float surface_below = 0.f;  // used when surface is set
  bool keep = false, surface = false;
};

// Bits of fuse_layer_simd's result: a voxel of the layer keeps its block (voxel_keeps_block with
// keep_below), or is near a surface (with surface_below).
constexpr int kRowKeeps = 1, kRowNearSurface = 2;

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {
// Fuses the frame into layer z of block b (its 64 voxels at that z): layer points to them, colors
// to their colours (nullptr: no colour fused). Not for a frame that carves free space (in.carve > 0).
int fuse_layer_simd(const FuseRowFrame& f, int3 b, int z, Voxel* layer, uchar3* colors);

// allocate_blocks' walks over the truncation bands of the 8 pixels (x0 + l, y) of a row, with its
// expressions in its order, so each walk is the scalar code's bit for bit: walks[l] is lane l's
// where bit l of the result is set (x0 + l inside the image, its reading within [min_depth,
// max_depth]); the other entries are left as they were.
constexpr int kBandLanes = 8;  // simd::kWidth
int band_walks_simd(const FrameInput& in, const VoxelGeometry& geom, int x0, int y, BlockWalk walks[kBandLanes]);
}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
#endif
