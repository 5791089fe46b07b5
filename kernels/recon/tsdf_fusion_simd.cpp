// The CPU's fusion rows on 8 lanes (tsdf_fusion_simd.hpp): fuse_voxel (tsdf_fusion.inl) for the
// 8 voxels of a block row at once, lane l the voxel at x = l.
#include "kernels/recon/tsdf_fusion_simd.hpp"

#include <cstring>

#include "core/simd.hpp"

namespace seamless::kernels {

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {

using simd::vf, simd::vi, simd::vm;

namespace {
// A row's 8 voxels, {sdf, weight} interleaved in the pool, as two vectors, and back.
SEAMLESS_SIMD_INL void load_row(const Voxel* v, vf& sdf, vf& wt) {
  simd::f8 lo, hi;
  std::memcpy(&lo, v, sizeof lo);
  std::memcpy(&hi, v + 4, sizeof hi);
  simd::deinterleave(lo, hi, sdf, wt);
}
SEAMLESS_SIMD_INL void store_row(Voxel* v, vf sdf, vf wt) {
  const simd::f8 lo = __builtin_shufflevector(sdf.v, wt.v, 0, 8, 1, 9, 2, 10, 3, 11);
  const simd::f8 hi = __builtin_shufflevector(sdf.v, wt.v, 4, 12, 5, 13, 6, 14, 7, 15);
  std::memcpy(v, &lo, sizeof lo);
  std::memcpy(v + 4, &hi, sizeof hi);
}

// Fuses the frame into the 8 voxels of row (y, z), whose values sdf and wt hold (and then their
// values after the frame); row points to them in the pool, colors to their colours (nullptr:
// none). ax: the x terms of camera_T_world's three rows, R[r][0] * x, for the block's 8 x (the
// same products for every row of the block).
SEAMLESS_SIMD_INL void fuse_row(const FuseRowFrame& f, const vf ax[3], float py, float pz, Voxel* row, uchar3* colors,
                                vf& sdf_v, vf& wt) {
  const FrameInput& in = f.in;
  const mat3& R = f.camera_T_world.R;
  const vec3 t = f.camera_T_world.t;
  const float mu = f.geom.truncation;
  // camera_T_world * p = R p + t, each row's dot product in core/math.hpp's order.
  const vf cx = ax[0] + vf(R.m[0][1] * py) + vf(R.m[0][2] * pz) + vf(t.x);
  const vf cy = ax[1] + vf(R.m[1][1] * py) + vf(R.m[1][2] * pz) + vf(t.y);
  const vf cz = ax[2] + vf(R.m[2][1] * py) + vf(R.m[2][2] * pz) + vf(t.z);
  vm m = cz > vf(0.f);
  // K.project, then the nearest pixel (floor_int of +0.5, which also holds a lane behind the
  // camera, inf or NaN, to a far index that the bounds below reject).
  const vi u = simd::floor_int(vf(in.K.fx) * cx / cz + vf(in.K.cx) + vf(0.5f));
  const vi w = simd::floor_int(vf(in.K.fy) * cy / cz + vf(in.K.cy) + vf(0.5f));
  m = m & (u >= 0) & (w >= 0) & (u < in.depth.width) & (w < in.depth.height);
  const int in_image = simd::bits(m);
  if (!in_image) return;
  vf d(0.f);
  for (int l = 0; l < simd::kWidth; ++l)
    if (in_image >> l & 1) d.v[l] = in.depth(u[l], w[l]);
  m = m & (d >= vf(in.min_depth)) & (d <= vf(in.max_depth));
  const vf sdf = d - cz;
  m = m & !(sdf < vf(-mu));  // occluded: behind the surface by more than the truncation
  if (!simd::bits(m)) return;
  if (colors && in.rgb.data) {  // colour only near the surface, a few lanes of a row: one at a time
    const int near = simd::bits(m & (sdf < vf(mu)));
    for (int l = 0; l < simd::kWidth; ++l)
      if (near >> l & 1) colors[l] = blend_color(colors[l], in.rgb(u[l], w[l]), wt[l]);
  }
  sdf_v = select(m, running_average(sdf_v, wt, min_of(sdf, vf(mu))), sdf_v);
  wt = select(m, min_of(wt + vf(1.f), vf(f.max_weight)), wt);
  store_row(row, sdf_v, wt);
}

// voxel_keeps_block for a row's 8 voxels, as fuse_layer_simd's flag bits.
SEAMLESS_SIMD_INL int row_flags(const FuseRowFrame& f, vf sdf, vf wt) {
  const vm observed = wt > vf(0.f);
  const vf a = abs(sdf);
  int flags = 0;
  if (f.keep && simd::bits(observed & (a < vf(f.keep_below)))) flags |= kRowKeeps;
  if (f.surface && simd::bits(observed & (a < vf(f.surface_below)))) flags |= kRowNearSurface;
  return flags;
}
}  // namespace

int fuse_layer_simd(const FuseRowFrame& f, int3 b, int z, Voxel* layer, uchar3* colors) {
  static_assert(simd::kWidth == kBlockSide && sizeof(Voxel) == 2 * sizeof(float));
  const mat3& R = f.camera_T_world.R;
  // The voxel centres in world units, geom.to_world (origin + g * voxel_size) per axis.
  vf gx;
  for (int l = 0; l < simd::kWidth; ++l) gx.v[l] = static_cast<float>(b.x * 8 + l);
  const vf px = vf(f.geom.origin.x) + gx * vf(f.geom.voxel_size);
  const vf ax[3] = {vf(R.m[0][0]) * px, vf(R.m[1][0]) * px, vf(R.m[2][0]) * px};
  const float pz = f.geom.origin.z + static_cast<float>(b.z * 8 + z) * f.geom.voxel_size;
  const int wanted = (f.keep ? kRowKeeps : 0) | (f.surface ? kRowNearSurface : 0);
  int flags = 0;
  for (int y = 0; y < kBlockSide; ++y) {
    const float py = f.geom.origin.y + static_cast<float>(b.y * 8 + y) * f.geom.voxel_size;
    const int r = y * kBlockSide;  // the row's first voxel in the layer
    vf sdf, wt;
    load_row(layer + r, sdf, wt);
    fuse_row(f, ax, py, pz, layer + r, colors ? colors + r : nullptr, sdf, wt);
    // Every row's flags, changed or not, as the scalar loop tests every voxel (until both are set).
    if (flags != wanted) flags |= row_flags(f, sdf, wt);
  }
  return flags;
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
