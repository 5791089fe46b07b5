// The CPU's march on 8 lanes (tsdf_march_simd.hpp): march_ray (tsdf_march.hpp) for 8 rays at
// once, lane l the ray r[l], each lane's state updated by the scalar loop's expressions.
#include "kernels/recon/tsdf_march_simd.hpp"

#include <cstring>

#include "core/simd.hpp"
#include "kernels/recon/voxel_simd.hpp"

#if SEAMLESS_SIMD_X86
#include <immintrin.h>
#endif

namespace seamless::kernels {

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {

using simd::i8, simd::f8, simd::vf, simd::vi, simd::vm, simd::v3;

namespace {
typedef long long q4 __attribute__((vector_size(32)));
typedef std::int32_t i4 __attribute__((vector_size(16)));
typedef unsigned u8 __attribute__((vector_size(32)));  // lanes of unsigned ints

struct vi3 {
  i8 x, y, z;
};

// Lane l: p[idx[l]] where m holds, else -1.
SEAMLESS_SIMD_INL i8 gather_index(const std::int32_t* p, i8 idx, vm m) {
#if SEAMLESS_SIMD_X86
  return reinterpret_cast<i8>(_mm256_mask_i32gather_epi32(
      reinterpret_cast<__m256i>(i8{} - 1), p, reinterpret_cast<__m256i>(idx), reinterpret_cast<__m256i>(m.v), 4));
#else
  i8 r = i8{} - 1;
  for (int l = 0; l < simd::kWidth; ++l)
    if (m.v[l]) r[l] = p[idx[l]];
  return r;
#endif
}

// find_block lane by lane for the lanes of m (-1 elsewhere): the window's entry where the block
// is inside it, the table's answer elsewhere (WindowedHashAccess::find_block).
SEAMLESS_SIMD_INL i8 find_blocks(const WindowedHashAccess& a, vi3 b, vm m) {
  const BlockWindow& w = a.window;
  // Unsigned, as BlockWindow::entry: the compares catch negatives too, and the entry of a lane
  // outside (not read) wraps harmlessly; inside, it fits in 32 bits (simd_marchable).
  const u8 x = reinterpret_cast<u8>(b.x) - static_cast<unsigned>(w.origin.x),
           y = reinterpret_cast<u8>(b.y) - static_cast<unsigned>(w.origin.y),
           z = reinterpret_cast<u8>(b.z) - static_cast<unsigned>(w.origin.z);
  const unsigned side = static_cast<unsigned>(w.side);
  const vm inside{reinterpret_cast<i8>((x < side) & (y < side) & (z < side))};
  i8 r = gather_index(w.index, reinterpret_cast<i8>(x + side * (y + side * z)), m & inside);
  const int outside = simd::bits(m & !inside);
  if (outside)
    for (int l = 0; l < simd::kWidth; ++l)
      if (outside >> l & 1) r[l] = a.HashAccess::find_block(int3{b.x[l], b.y[l], b.z[l]});
  return r;
}

// near_surface lane by lane for the lanes of m (blocks >= 0); true elsewhere.
SEAMLESS_SIMD_INL vm near_flags(const WindowedHashAccess& a, i8 block, vm m) {
  if (!a.near_surface) return {i8{} - 1};
  return {~m.v | (gather_index(a.near_surface, block, m) != 0)};
}

// The words (Voxel, voxel_simd.hpp) of voxel block[l] * 512 + local[l] of the pool for the lanes
// of m, 0 (unobserved) elsewhere. The index is formed in 64 bits: a pool can hold more than 2^31
// voxels.
SEAMLESS_SIMD_INL i8 load_voxels(const Voxel* pool, i8 block, i8 local, vm m) {
  static_assert(kBlockVoxels == 512);
#if SEAMLESS_SIMD_X86
  auto lanes = [](i8 v, int h) -> i4 {  // lanes 4h to 4h + 3
    return h ? __builtin_shufflevector(v, v, 4, 5, 6, 7) : __builtin_shufflevector(v, v, 0, 1, 2, 3);
  };
  auto half = [&](i8 v, int h) { return __builtin_convertvector(lanes(v, h), q4); };  // as 64-bit ints
  const int* base = reinterpret_cast<const int*>(pool);
  const q4 i0 = half(block, 0) * 512 + half(local, 0), i1 = half(block, 1) * 512 + half(local, 1);
  const i4 lo = reinterpret_cast<i4>(_mm256_mask_i64gather_epi32(
      _mm_setzero_si128(), base, reinterpret_cast<__m256i>(i0), reinterpret_cast<__m128i>(lanes(m.v, 0)), 4));
  const i4 hi = reinterpret_cast<i4>(_mm256_mask_i64gather_epi32(
      _mm_setzero_si128(), base, reinterpret_cast<__m256i>(i1), reinterpret_cast<__m128i>(lanes(m.v, 1)), 4));
  return __builtin_shufflevector(lo, hi, 0, 1, 2, 3, 4, 5, 6, 7);
#else
  i8 r = {};
  for (int l = 0; l < simd::kWidth; ++l)
    if (m.v[l]) {
      std::int32_t word;
      std::memcpy(&word, pool + static_cast<std::int64_t>(block[l]) * kBlockVoxels + local[l], sizeof word);
      r[l] = word;
    }
  return r;
#endif
}

SEAMLESS_SIMD_INL i8 local_index(i8 x, i8 y, i8 z) { return (x & 7) + 8 * (y & 7) + 64 * (z & 7); }

// sample_tsdf_in (the CPU's order) for the lanes of m: the cell of voxel g0 (in block b, index
// i0), trilinear at q into f. Returns the lanes that have a value.
SEAMLESS_SIMD_INL vm sample_lanes(const WindowedHashAccess& a, v3 q, vi3 g0, vi3 b, i8 i0, vm m, vf& f) {
  if (!simd::bits(m)) return m;
  // The cell reaches into the next block along the axes where g0 is a block's last voxel (cell_voxels).
  const i8 ex = (g0.x & 7) == 7, ey = (g0.y & 7) == 7, ez = (g0.z & 7) == 7;  // -1 where true
  // The eight loads go out together, their cache misses overlapping (the scalar loop reads corner
  // 0 first and stops there when it is unobserved: one wait more a sample, for the lanes a wait
  // less); a lane has a value when all eight corners are allocated and observed.
  vf d[8];
  vm all = m;
  // blk[k]: the block of corner k, b + (k&1 & ex, k>>1&1 & ey, k>>2 & ez). A lane looks a block up
  // only for the corners whose offset axes are all its edge axes (mostly corners 1, 2 and 4): a
  // corner offset along an axis where the lane's cell stays in its block shares the block of the
  // corner without that offset, found before it (k ^ that axis's bit < k).
  const vm axis_edge[3] = {m & vm{ex}, m & vm{ey}, m & vm{ez}};
  i8 blk[8];
  blk[0] = i0;
  for (int k = 1; k < 8; ++k) {
    vm own = m;
    i8 shared = i0;
    for (int j = 0; j < 3; ++j)
      if (k >> j & 1) {
        own = own & axis_edge[j];
        shared = select(!axis_edge[j], vi(blk[k ^ (1 << j)]), vi(shared)).v;
      }
    blk[k] = shared;
    if (simd::bits(own)) {
      const i8 ox = k & 1 ? i8{} + 1 : i8{}, oy = k & 2 ? i8{} + 1 : i8{}, oz = k & 4 ? i8{} + 1 : i8{};
      blk[k] = select(own, vi(find_blocks(a, vi3{b.x + ox, b.y + oy, b.z + oz}, own)), vi(shared)).v;
    }
  }
  for (int k = 0; k < 8; ++k) {
    const i8 ik = blk[k];
    const vm mk = m & vm{ik >= 0};
    const i8 local = local_index(g0.x + (k & 1), g0.y + (k >> 1 & 1), g0.z + (k >> 2));
    const i8 raw = load_voxels(a.voxels, ik, local, mk);
    d[k] = voxel_steps(raw);
    all = all & mk & vm{voxel_weights(raw) != 0};  // voxel_observed
  }
  const vf fx = q.x - vf(__builtin_convertvector(g0.x, f8)), fy = q.y - vf(__builtin_convertvector(g0.y, f8)),
           fz = q.z - vf(__builtin_convertvector(g0.z, f8));
  // Trilinear as 7 lerps along x, then y, then z, in steps, then in metres (sample_tsdf_in's expressions).
  auto lerp = [](vf p, vf q, vf t) { return p + t * (q - p); };
  const vf x0 = lerp(d[0], d[1], fx), x1 = lerp(d[2], d[3], fx), x2 = lerp(d[4], d[5], fx), x3 = lerp(d[6], d[7], fx);
  f = lerp(lerp(x0, x1, fy), lerp(x2, x3, fy), fz) * vf(a.geom.truncation / kSdfSteps);
  return all;
}

// The march waits on its voxel loads (a frame's fusion has just streamed every visible block
// through the caches): a lane's first sample in a block asks for the whole block (32 lines), which
// its next samples and the neighbouring rays' mostly read. The lanes of m sample in blocks i0;
// last holds each lane's block before (a block is fetched once for the lanes that share it).
SEAMLESS_SIMD_INL void prefetch_blocks(const WindowedHashAccess& a, i8 i0, vm m, i8& last) {
  const int fresh = simd::bits(m & vm{i0 != last});
  if (!fresh) return;
  std::int32_t fetched = -1;
  for (int l = 0; l < simd::kWidth; ++l)
    if ((fresh >> l & 1) && i0[l] != fetched) {
      fetched = i0[l];
      const char* p = reinterpret_cast<const char*>(a.voxels + static_cast<std::int64_t>(fetched) * kBlockVoxels);
      for (int k = 0; k < kBlockVoxels * static_cast<int>(sizeof(Voxel)) / 64; ++k) __builtin_prefetch(p + 64 * k);
    }
  last = m.v ? i0 : last;
}

// block_exit lane by lane.
SEAMLESS_SIMD_INL vf block_exit_lanes(v3 o, v3 d, v3 inv_d, vi3 b) {
  vf t(1e30f);
  const vf lo[3] = {vf(__builtin_convertvector(b.x, f8)) * vf(8.f), vf(__builtin_convertvector(b.y, f8)) * vf(8.f),
                    vf(__builtin_convertvector(b.z, f8)) * vf(8.f)};
  const vf oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z}, ii[3] = {inv_d.x, inv_d.y, inv_d.z};
  for (int k = 0; k < 3; ++k) {
    t = select(dd[k] > vf(0.f), simd::min_of(t, (lo[k] + vf(8.f) - oo[k]) * ii[k]), t);
    t = select(dd[k] < vf(0.f), simd::min_of(t, (lo[k] - oo[k]) * ii[k]), t);
  }
  return t;
}

SEAMLESS_SIMD_INL vi3 floor_lanes(v3 q) {
  return {simd::floor_int(q.x).v, simd::floor_int(q.y).v, simd::floor_int(q.z).v};
}
}  // namespace

void march_row_simd(const WindowedHashAccess& a, int x0, int y, int n, const Intrinsics& K, const SE3& world_T_camera,
                    float min_depth, float max_depth, const RayIntervals& iv, PixelRay* r, bool* hit, float* zh) {
  // pixel_ray and march_steps (tsdf_march.hpp) lane by lane: lane l the ray of pixel (x0 + l, y);
  // lanes >= n repeat pixel x0 and stay idle.
  const VoxelGeometry& g = a.geom;
  vf px;
  for (int l = 0; l < simd::kWidth; ++l) px.v[l] = static_cast<float>(x0 + (l < n ? l : 0));
  // K.unproject(x, y, 1): ((u - cx) * 1) / fx
  const v3 dir_c{(px - vf(K.cx)) * vf(1.f) / vf(K.fx), vf((static_cast<float>(y) - K.cy) * 1.f / K.fy), vf(1.f)};
  const mat3& R = world_T_camera.R;
  const vf vs(g.voxel_size);
  const v3 o = simd::broadcast(g.to_voxel(world_T_camera.t));
  const v3 d{dot(simd::broadcast(R.row(0)), dir_c) / vs, dot(simd::broadcast(R.row(1)), dir_c) / vs,
             dot(simd::broadcast(R.row(2)), dir_c) / vs};
  const vf dlen = simd::length(d);  // voxels per metre of depth
  const vf min_step = vf(0.5f) / dlen;
  vf z(min_depth), z_end(max_depth);
  if (iv.bits) {  // the tile's interval (fmaxf, fminf: never NaN here)
    vf z_near, z_far;
    for (int l = 0; l < simd::kWidth; ++l) {
      const std::int64_t t = iv.tile_of(x0 + (l < n ? l : 0), y);
      z_near.v[l] = bits_float(iv.bits[2 * t]), z_far.v[l] = bits_float(iv.bits[2 * t + 1]);
    }
    z = simd::max_of(z, z_near - min_step);
    z_end = select(z_far > vf(0.f), simd::min_of(z_end, z_far + min_step), vf(0.f));
  }
  const vf unobserved_step = simd::max_of(min_step, vf(0.5f * g.truncation) / (dlen * vs));
  const vf step_per_sdf = vf(0.8f) / (dlen * vs);
  const v3 inv_d{vf(1.f) / d.x, vf(1.f) / d.y, vf(1.f) / d.z};
  for (int l = 0; l < n; ++l)
    r[l].o = simd::lane(o, l), r[l].d = simd::lane(d, l), r[l].z = z[l], r[l].z_end = z_end[l];
  vf z_prev(0.f), f_prev(0.f), ta(0.f), fa(0.f), tb(0.f), fb(0.f);
  vi refine(-1);  // -1: marching; else regula falsi steps taken
  vm have_prev{i8{}}, prev_near{i8{}};
  int live = (1 << n) - 1, found = 0;  // lanes still going; lanes that ended on a hit
  i8 last_block = i8{} - 1;            // the block of each lane's last sample
  for (int it = 0;; ++it) {
    // march_ray's loop condition, lane by lane.
    const vm refining = refine >= vi(0);
    live &= simd::bits(refining | (vm{i8{} - (it < kMaxMarchSteps ? 1 : 0)} & (z < z_end)));
    if (!live) break;
    const vm L = simd::from_bits(live);
    const v3 q = o + d * z;
    const vi3 g0 = floor_lanes(q), b{g0.x >> 3, g0.y >> 3, g0.z >> 3};
    const i8 i0 = find_blocks(a, b, L);
    const vm allocated = L & vm{i0 >= 0};
    const vm near = allocated & (refining | near_flags(a, i0, allocated));
    const vm skip = (!allocated) | ((!near) & !(have_prev & prev_near));
    vf f(0.f);
    prefetch_blocks(a, i0, L & !skip, last_block);
    const vm sampled = sample_lanes(a, q, g0, b, i0, L & !skip, f);

    // Refining lanes: regula falsi between the bracket's ends; no value ends it at the last estimate.
    const vm rl = L & refining, rs = rl & sampled, pos = f > vf(0.f);
    ta = select(rs & pos, z, ta), fa = select(rs & pos, f, fa);
    tb = select(rs & !pos, z, tb), fb = select(rs & !pos, f, fb);
    z = select(rs, ta + (tb - ta) * fa / (fa - fb), z);
    refine = select(rs, refine + vi(1), refine);
    const int ended = simd::bits((rl & !sampled) | (rs & (refine == vi(kRefineSteps))));
    found |= ended, live &= ~ended;

    // Marching lanes.
    const vm ml = L & !refining;
    const vm ms = ml & skip;  // empty space: skip the whole block
    z = select(ms, simd::max_of(block_exit_lanes(o, d, inv_d, b), z) + min_step * vf(0.1f), z);
    const vm mu = ml & !skip & !sampled;  // unobserved: a fixed step
    z = select(mu, z + unobserved_step, z);
    have_prev = have_prev & !(ms | mu);
    const vm msd = ml & sampled;
    const vm bracket = msd & have_prev & (f_prev > vf(0.f)) & (f <= vf(0.f));
    ta = select(bracket, z_prev, ta), fa = select(bracket, f_prev, fa);
    tb = select(bracket, z, tb), fb = select(bracket, f, fb);
    refine = select(bracket, vi(0), refine);
    const vm step = msd & !bracket;
    z_prev = select(step, z, z_prev), f_prev = select(step, f, f_prev);
    have_prev = have_prev | step, prev_near = select(step, near, prev_near);
    z = select(bracket, ta + (tb - ta) * fa / (fa - fb),
               select(step, z + simd::max_of(simd::abs(f) * step_per_sdf, min_step), z));
  }
  for (int l = 0; l < n; ++l) hit[l] = found >> l & 1, zh[l] = z[l];
}

namespace {
// Vertices and depths of pixels (x0 - 1 + k, yy), k < m, on lanes (lane k of v and z, or of the
// shifted copies the caller takes); pixels outside the image read as no reading (depth 0), which
// vertex_map_normal treats as it treats an outside neighbour.
template <int M> struct RowCopy {
  vec3 v[M];
  float z[M];
  RowCopy(View2D<const vec3> vtx, View2D<const float> depth, int x_first, int yy) {
    for (int k = 0; k < M; ++k) {
      const int x = x_first + k;
      const bool in = vtx.inside(x, yy);
      v[k] = in ? vtx(x, yy) : vec3{0.f, 0.f, 0.f};
      z[k] = in ? depth(x, yy) : 0.f;
    }
  }
  v3 lanes_v(int k0) const { return simd::load_v3(v + k0); }
  vf lanes_z(int k0) const {
    vf r;
    std::memcpy(&r.v, z + k0, sizeof r.v);
    return r;
  }
};

// vertex_map_normal's axis_diff on lanes: the difference along an axis from the neighbours p (+)
// and m (-) with depths zp and zm, each usable when it has a reading and lies within the jump.
SEAMLESS_SIMD_INL vm axis_lanes(v3 v, v3 p, vf zp, v3 m, vf zm, vf jump2, v3& d) {
  const vm hp = (zp > vf(0.f)) & (length2(p - v) <= jump2), hm = (zm > vf(0.f)) & (length2(m - v) <= jump2);
  d = select(hp & hm, p - m, select(hp, p - v, v - m));
  return hp | hm;
}
}  // namespace

void normals_row_simd(View2D<const vec3> vtx, View2D<const float> depth, int x0, int y, int n, vec3 eye,
                      float jump_per_metre, View2D<vec3> normal) {
  const RowCopy<simd::kWidth + 2> row(vtx, depth, x0 - 1, y);
  const RowCopy<simd::kWidth> up(vtx, depth, x0, y - 1), down(vtx, depth, x0, y + 1);
  const v3 v = row.lanes_v(1);
  const vf z = row.lanes_z(1);
  const vf jump = vf(jump_per_metre) * z, jump2 = jump * jump;
  v3 du, dv;
  const vm ok = (z > vf(0.f)) &
                axis_lanes(v, row.lanes_v(2), row.lanes_z(2), row.lanes_v(0), row.lanes_z(0), jump2, du) &
                axis_lanes(v, down.lanes_v(0), down.lanes_z(0), up.lanes_v(0), up.lanes_z(0), jump2, dv);
  // normalize(cross(dv, du)), facing the eye.
  const v3 c = cross(dv, du);
  const vf len = simd::length(c);
  const vm long_enough = len > vf(0.f);
  v3 nrm = select(long_enough, v3{c.x / len, c.y / len, c.z / len}, v3{vf(0.f), vf(0.f), vf(0.f)});
  nrm = select(dot(nrm, simd::broadcast(eye) - v) < vf(0.f), nrm * vf(-1.f), nrm);
  nrm = select(ok, nrm, v3{vf(0.f), vf(0.f), vf(0.f)});
  for (int l = 0; l < n; ++l) normal(x0 + l, y) = simd::lane(nrm, l);
}

}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
