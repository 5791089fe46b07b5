// The CPU's fusion rows on 8 lanes (tsdf_fusion_simd.hpp): fuse_voxel (tsdf_fusion.inl) for the
// 8 voxels of a block row at once, lane l the voxel at x = l.
#include "kernels/recon/tsdf_fusion_simd.hpp"

#include <cstring>
#if SEAMLESS_SIMD_X86
#include <immintrin.h>
#endif

#include "core/simd.hpp"
#include "kernels/recon/voxel_simd.hpp"

namespace seamless::kernels {

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {

using simd::vf, simd::vi, simd::vm, simd::v3;

namespace {
// in.depth(u, w) lane by lane for the lanes of m (0 elsewhere): one gather instruction instead of
// eight loads and inserts.
SEAMLESS_SIMD_INL vf gather_depth(const View2D<const float>& depth, vi u, vi w, vm m) {
  const simd::i8 idx = w.v * static_cast<std::int32_t>(depth.pitch) + u.v;  // < 2^31: images are small
#if SEAMLESS_SIMD_X86
  return reinterpret_cast<simd::f8>(_mm256_mask_i32gather_ps(
      _mm256_setzero_ps(), depth.data, reinterpret_cast<__m256i>(idx), reinterpret_cast<__m256>(m.v), 4));
#else
  vf d(0.f);
  for (int l = 0; l < simd::kWidth; ++l)
    if (m.v[l]) d.v[l] = depth.data[idx[l]];
  return d;
#endif
}

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
// same products for every row of the block). size: the depth image's width and height, broadcast
// once a layer (read again each row, behind the rows' colour stores, GCC assembled them through
// memory, and the vector load then waited for the scalar stores: a fifth of this loop's time).
SEAMLESS_SIMD_INL void fuse_row(const FuseRowFrame& f, const vf ax[3], const vi size[2], float py, float pz, Voxel* row,
                                uchar3* colors, vf& steps, vf& wt) {
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
  m = m & (u >= 0) & (w >= 0) & (u < size[0]) & (w < size[1]);
  const int in_image = simd::bits(m);
  if (!in_image) return;
  const vf d = gather_depth(in.depth, u, w, m);
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
  const vi size[2] = {vi(f.in.depth.width), vi(f.in.depth.height)};
  const int wanted = (f.keep ? kRowKeeps : 0) | (f.surface ? kRowNearSurface : 0);
  int flags = 0;
  for (int y = 0; y < kBlockSide; ++y) {
    const float py = f.geom.origin.y + static_cast<float>(b.y * 8 + y) * f.geom.voxel_size;
    const int r = y * kBlockSide;  // the row's first voxel in the layer
    vf steps, wt;
    load_row(layer + r, steps, wt);
    fuse_row(f, ax, size, py, pz, layer + r, colors ? colors + r : nullptr, steps, wt);
    // Every row's flags, changed or not, as the scalar loop tests every voxel (until both are set).
    if (flags != wanted) flags |= row_flags(f, steps, wt);
  }
  return flags;
}

int band_walks_simd(const FrameInput& in, const VoxelGeometry& g, int x0, int y, BlockWalk walks[kBandLanes]) {
  static_assert(kBandLanes == simd::kWidth);
  const int n = in.depth.width - x0 < simd::kWidth ? in.depth.width - x0 : simd::kWidth;
  vf d(0.f), px;
  for (int l = 0; l < simd::kWidth; ++l) {
    d.v[l] = l < n ? in.depth(x0 + l, y) : 0.f;
    px.v[l] = static_cast<float>(x0 + l);
  }
  const int lanes = simd::bits((d >= vf(in.min_depth)) & (d <= vf(in.max_depth))) & ((1 << n) - 1);
  if (!lanes) return 0;
  // K.unproject(x, y, d), r = mu / length(p), and the band's ends world_T_camera * (p (1 -+ r)) in
  // block units: R q + t (each row's dot product in core/math.hpp's order), less the origin, times
  // to_block.
  const Intrinsics& K = in.K;
  const v3 p{(px - vf(K.cx)) * d / vf(K.fx), vf(static_cast<float>(y) - K.cy) * d / vf(K.fy), d};
  const vf r = vf(g.truncation) / simd::length(p);
  const mat3& R = in.world_T_camera.R;
  const vec3 t = in.world_T_camera.t;
  const vf to_block(1.f / (g.voxel_size * kBlockSide));
  auto end = [&](vf s) {
    const v3 q = p * s;
    return v3{(dot(simd::broadcast(R.row(0)), q) + vf(t.x) - vf(g.origin.x)) * to_block,
              (dot(simd::broadcast(R.row(1)), q) + vf(t.y) - vf(g.origin.y)) * to_block,
              (dot(simd::broadcast(R.row(2)), q) + vf(t.z) - vf(g.origin.z)) * to_block};
  };
  const v3 a = end(vf(1.f) - r), b = end(vf(1.f) + r);
  // block_walk lane by lane.
  const vf af[3] = {a.x, a.y, a.z}, bf[3] = {b.x, b.y, b.z};
  simd::i8 c[3], e[3], s[3], steps = simd::i8{} + 1;
  vf tt[3], dt[3];
  const vf inf(1e30f);
  for (int k = 0; k < 3; ++k) {
    c[k] = simd::floor_int(af[k]).v, e[k] = simd::floor_int(bf[k]).v;
    const simd::i8 span = e[k] - c[k];
    steps += span < 0 ? -span : span;
    const vf dk = bf[k] - af[k];
    const vm up = dk > vf(0.f), moves{dk.v != simd::f8{}};
    s[k] = up.v ? simd::i8{} + 1 : simd::i8{} - 1;
    const vf face(__builtin_convertvector(c[k] + (up.v & 1), simd::f8));
    tt[k] = select(moves, (face - af[k]) / dk, inf);
    dt[k] = select(moves, simd::abs(vf(1.f) / dk), inf);
  }
  for (int l = 0; l < simd::kWidth; ++l) {
    if (!(lanes >> l & 1)) continue;
    BlockWalk& w = walks[l];
    w.c = {c[0][l], c[1][l], c[2][l]}, w.e = {e[0][l], e[1][l], e[2][l]}, w.s = {s[0][l], s[1][l], s[2][l]};
    w.t = {tt[0][l], tt[1][l], tt[2][l]}, w.dt = {dt[0][l], dt[1][l], dt[2][l]};
    w.n_max = steps[l] > 64 ? steps[l] : 64;
  }
  return lanes;
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
