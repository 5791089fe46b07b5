// The CPU's fusion rows on 8 lanes (tsdf_fusion_simd.hpp): fuse_voxel (tsdf_fusion.inl) for the
// 8 voxels of a block row at once, lane l the voxel at x = l.
#include "kernels/recon/tsdf_fusion_simd.hpp"

#include <cstring>

#include "core/simd.hpp"
#include "kernels/recon/voxel_simd.hpp"

namespace seamless::kernels {

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {

using simd::vf, simd::vi, simd::vm;

namespace {
// A row's 8 voxels (tsdf_fusion_simd.hpp) as their distances in steps and their weights, and back.
SEAMLESS_SIMD_INL void load_row(const Voxel* v, vf& steps, vf& wt) {
  simd::i8 raw;
  std::memcpy(&raw, v, sizeof raw);
  steps = voxel_steps(raw), wt = __builtin_convertvector(voxel_weights(raw), simd::f8);
}
SEAMLESS_SIMD_INL void store_row(Voxel* v, simd::i8 steps, vf wt) {
  const simd::i8 raw = pack_voxels(steps, __builtin_convertvector(wt.v, simd::i8));
  std::memcpy(v, &raw, sizeof raw);
}

// Fuses the frame into the 8 voxels of row (y, z), whose distances (in steps) and weights steps and
// wt hold (and then their values after the frame); row points to them in the pool, colors to their colours (nullptr:
// none). ax: the x terms of camera_T_world's three rows, R[r][0] * x, for the block's 8 x (the
// same products for every row of the block).
SEAMLESS_SIMD_INL void fuse_row(const FuseRowFrame& f, const vf ax[3], float py, float pz, Voxel* row, uchar3* colors,
                                vf& steps, vf& wt) {
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
  // fuse_tsdf: the running average in steps, rounded to the nearest step.
  const vf to_steps(kSdfSteps / mu), q = steps;
  const simd::i8 fused = sdf_steps(q + (min_of(sdf, vf(mu)) * to_steps - q) / (wt + vf(1.f)));
  steps = select(m, vf(__builtin_convertvector(fused, simd::f8)), q);
  wt = select(m, min_of(wt + vf(1.f), vf(f.max_weight)), wt);
  store_row(row, __builtin_convertvector(steps.v, simd::i8), wt);
}

// voxel_keeps_block for a row's 8 voxels, as fuse_layer_simd's flag bits.
SEAMLESS_SIMD_INL int row_flags(const FuseRowFrame& f, vf steps, vf wt) {
  const vm observed = wt > vf(0.f);
  const vf a = abs(steps * vf(f.geom.truncation / kSdfSteps));  // voxel_sdf
  int flags = 0;
  if (f.keep && simd::bits(observed & (a < vf(f.keep_below)))) flags |= kRowKeeps;
  if (f.surface && simd::bits(observed & (a < vf(f.surface_below)))) flags |= kRowNearSurface;
  return flags;
}
}  // namespace

int fuse_layer_simd(const FuseRowFrame& f, int3 b, int z, Voxel* layer, uchar3* colors) {
  static_assert(simd::kWidth == kBlockSide);
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
    vf steps, wt;
    load_row(layer + r, steps, wt);
    fuse_row(f, ax, py, pz, layer + r, colors ? colors + r : nullptr, steps, wt);
    // Every row's flags, changed or not, as the scalar loop tests every voxel (until both are set).
    if (flags != wanted) flags |= row_flags(f, steps, wt);
  }
  return flags;
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
