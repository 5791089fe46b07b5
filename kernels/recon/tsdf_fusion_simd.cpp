// The CPU's fusion rows on 8 lanes (tsdf_fusion_simd.hpp): fuse_voxel (tsdf_fusion.inl) for the
// 8 voxels of a block row at once, lane l the voxel at x = l.
#include "kernels/recon/tsdf_fusion_simd.hpp"

#include <cstring>

#include "kernels/physics/simd.hpp"

namespace seamless::kernels {

#if SEAMLESS_SIMD_X86
#pragma GCC push_options
#pragma GCC target("avx2")
#endif
namespace detail {

namespace {
using simd::vf, simd::vi, simd::vm;

SEAMLESS_SIMD_INL vm operator!(vm m) { return {~m.v}; }
SEAMLESS_SIMD_INL vm operator>=(vi a, int b) { return {a.v >= vi(b).v}; }
SEAMLESS_SIMD_INL vm operator<(vi a, int b) { return {a.v < vi(b).v}; }
// min_of(a, b) of core/math.hpp, lane by lane: a < b ? a : b.
SEAMLESS_SIMD_INL vf min_of(vf a, vf b) { return select(a < b, a, b); }
// fabsf lane by lane, up to the sign of a zero (which no comparison below sees).
SEAMLESS_SIMD_INL vf abs(vf a) { return select(a < vf(0.f), -a, a); }
}  // namespace

int fuse_row_simd(const FuseRowFrame& f, int3 b, int y, int z, Voxel* row, uchar3* colors) {
  static_assert(simd::kWidth == kBlockSide && sizeof(Voxel) == 2 * sizeof(float));
  const FrameInput& in = f.in;
  const mat3& R = f.camera_T_world.R;
  const vec3 t = f.camera_T_world.t;
  const float mu = f.geom.truncation;
  // The row's voxel centres in world units, geom.to_world (origin + g * voxel_size) per axis.
  vf gx;
  for (int l = 0; l < simd::kWidth; ++l) gx.v[l] = static_cast<float>(b.x * 8 + l);
  const vf px = vf(f.geom.origin.x) + gx * vf(f.geom.voxel_size);
  const float py = f.geom.origin.y + static_cast<float>(b.y * 8 + y) * f.geom.voxel_size;
  const float pz = f.geom.origin.z + static_cast<float>(b.z * 8 + z) * f.geom.voxel_size;
  // camera_T_world * p = R p + t, each row's dot product in core/math.hpp's order.
  auto camera_axis = [&](int r, float tr) {
    return vf(R.m[r][0]) * px + vf(R.m[r][1] * py) + vf(R.m[r][2] * pz) + vf(tr);
  };
  const vf cx = camera_axis(0, t.x), cy = camera_axis(1, t.y), cz = camera_axis(2, t.z);
  vm m = cz > vf(0.f);
  // K.project, then the nearest pixel (floor_int of +0.5, which also holds a lane behind the
  // camera, inf or NaN, to a far index that the bounds below reject).
  const vi u = simd::floor_int(vf(in.K.fx) * cx / cz + vf(in.K.cx) + vf(0.5f));
  const vi w = simd::floor_int(vf(in.K.fy) * cy / cz + vf(in.K.cy) + vf(0.5f));
  m = m & (u >= 0) & (w >= 0) & (u < in.depth.width) & (w < in.depth.height);
  vf d(0.f);
  const int in_image = simd::bits(m);
  for (int l = 0; l < simd::kWidth; ++l)
    if (in_image >> l & 1) d.v[l] = in.depth(u[l], w[l]);
  m = m & (d >= vf(in.min_depth)) & (d <= vf(in.max_depth));
  const vf sdf = d - cz;
  m = m & !(sdf < vf(-mu));  // occluded: behind the surface by more than the truncation
  // The row's voxels, {sdf, weight} interleaved, as two lanes of 8.
  simd::f8 lo, hi;
  std::memcpy(&lo, row, sizeof lo);
  std::memcpy(&hi, row + 4, sizeof hi);
  const vf old_sdf = __builtin_shufflevector(lo, hi, 0, 2, 4, 6, 8, 10, 12, 14);
  const vf wt = __builtin_shufflevector(lo, hi, 1, 3, 5, 7, 9, 11, 13, 15);
  const vf new_sdf = select(m, running_average(old_sdf, wt, min_of(sdf, vf(mu))), old_sdf);
  const vf new_wt = select(m, min_of(wt + vf(1.f), vf(f.max_weight)), wt);
  if (colors && in.rgb.data) {  // colour only near the surface, a few lanes of a row: one at a time
    const int near = simd::bits(m & (sdf < vf(mu)));
    for (int l = 0; l < simd::kWidth; ++l)
      if (near >> l & 1) colors[l] = blend_color(colors[l], in.rgb(u[l], w[l]), wt[l]);
  }
  lo = __builtin_shufflevector(new_sdf.v, new_wt.v, 0, 8, 1, 9, 2, 10, 3, 11);
  hi = __builtin_shufflevector(new_sdf.v, new_wt.v, 4, 12, 5, 13, 6, 14, 7, 15);
  std::memcpy(row, &lo, sizeof lo);
  std::memcpy(row + 4, &hi, sizeof hi);
  // voxel_keeps_block, lane by lane.
  const vm observed = new_wt > vf(0.f);
  const vf a = abs(new_sdf);
  int flags = 0;
  if (f.keep && simd::bits(observed & (a < vf(f.keep_below)))) flags |= kRowKeeps;
  if (f.surface && simd::bits(observed & (a < vf(f.surface_below)))) flags |= kRowNearSurface;
  return flags;
}

}  // namespace detail
#if SEAMLESS_SIMD_X86
#pragma GCC pop_options
#endif

}  // namespace seamless::kernels
