// The tiles' bodies: the families' pair helpers (included .inl files) on 8 lanes at once.
#include "core/exec_cpu.hpp"
#include "kernels/physics/fluid.inl"
#include "kernels/physics/grid.inl"

namespace seamless::kernels {

// ---- the CPU's SIMD tiles (core/simd.hpp) ------------------------------------------
// A tile is 8 consecutive sorted particles, one per lane, each walking its own list in list
// order; the pair terms are the scalar loops' functions over simd::vf, so the sums and states are
// bit-identical to the scalar loops. A tile takes the vector path only where all 8 particles are
// fluid with fluid-only lists (the fluid's interior and surface; mixed tiles run the scalar
// loops). Compiled for AVX2 (simd::cpu_simd() checks the CPU at run time).
SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {
// The tile at s0 if it can take the vector path: its list lengths, the shortest and the longest.
struct Tile {
  int s0, m[simd::kWidth], kmin, kmax;
};
inline bool fluid_tile(const SimViews& S, int s0, Tile& t) {
  if (s0 + simd::kWidth > S.n) return false;
  t.s0 = s0, t.kmin = 1 << 30, t.kmax = 0;
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    if (!phase::is(S.sphase[s], phase::kFluid) || S.nsolid[s] != 0 || S.nsnbr[s] != 0) return false;
    t.m[l] = S.nnbr[s];
    t.kmin = t.m[l] < t.kmin ? t.m[l] : t.kmin;
    t.kmax = t.m[l] > t.kmax ? t.m[l] : t.kmax;
  }
  return true;
}

// Entry k of each lane's list (the lane's own particle where k is past its list: a valid index
// whose terms the mask drops); in: the lanes whose list has an entry k.
template <bool Masked>
SEAMLESS_SIMD_INL void tile_entries(const SimViews& S, const Tile& t, int k, int* j, simd::vm& in) {
  for (int l = 0; l < simd::kWidth; ++l) {
    const int* list = S.nbrs(t.s0 + l);
    if constexpr (Masked) {
      const bool has = k < t.m[l];
      j[l] = has ? list[k * S.nbr_col] : t.s0 + l;
      in.v[l] = has ? -1 : 0;
    } else {
      j[l] = list[k * S.nbr_col];
    }
  }
}

// Gathers of entries j of a packed array: (xyz, w) of each lane.
SEAMLESS_SIMD_INL void gather_packed(const Packed* a, const int* j, simd::v3& xyz, simd::vf& w) {
  const void* e[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) e[l] = a + j[l];
  simd::load_transpose(e, xyz.x, xyz.y, xyz.z, w);
}

// acc += d where the lanes are in (all of them unless Masked).
template <bool Masked> SEAMLESS_SIMD_INL void tile_add(simd::v3& acc, const simd::v3& d, simd::vm in) {
  if constexpr (Masked) acc = select(in, acc + d, acc);
  else acc += d;
}

// The pair loop that every tile runs: pair(j, in, masked) for the entries k of the lanes' lists,
// j[l] = entry k of lane l, with masked = std::false_type while every lane has an entry k (k
// below the shortest list: no mask needed) and std::true_type after (in: the lanes that have one,
// tile_entries). What a tile gathers and sums is all in its pair function.
template <class Pair> SEAMLESS_SIMD_INL void tile_pairs(const SimViews& S, const Tile& t, Pair&& pair) {
  auto step = [&](int k, auto masked) __attribute__((always_inline)) {
    int j[simd::kWidth];
    simd::vm in;
    tile_entries<decltype(masked)::value>(S, t, k, j, in);
    pair(j, in, masked);
  };
  for (int k = 0; k < t.kmin; ++k) step(k, std::false_type{});
  for (int k = t.kmin; k < t.kmax; ++k) step(k, std::true_type{});
}

// vorticity_part of the tile's 8 particles (velocity_effects). False where the tile needs the
// scalar loops. The tiles keep nothing in pair_w: forces_tile recomputes the pairs' kernel values
// (on 8 lanes that costs less time than storing and reloading them, docs/PERFORMANCE.md; the
// scalar loops of tiles that decline keep using pair_w, and a tile
// declines in both passes or in neither).
bool vorticity_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  const float inv_rho0 = 1.f / S.c.rest_density, coh_c = -S.c.cohesion * inv_rho0;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0), vi = simd::load_v3(S.sv + s0);
  v3 tw{}, tn{}, tdv{};
  tile_pairs(
      S, t, [&](const int* j, simd::vm in, auto masked) __attribute__((always_inline)) {
        constexpr bool kMasked = decltype(masked)::value;
        v3 q, vj;
        simd::vf rho, hj;
        gather_packed(S.spd, j, q, rho);
        gather_packed(S.svh, j, vj, hj);
        const auto d = vorticity_pair<false>(W, inv_rho0, coh_c, p - q, vi, vj, hj);
        tile_add<kMasked>(tw, d.w, in);
        tile_add<kMasked>(tn, d.n, in);
        tile_add<kMasked>(tdv, d.dv, in);
      });
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    S.vort[s] = simd::lane(tw, l);
    S.vort_len[s] = length(S.vort[s]);
    S.cnormal[s] = simd::lane(tn, l);
    S.cnv[s] = Packed::of(S.cnormal[s], S.vort_len[s]);
    S.vtmp[s] = simd::lane(tdv, l);
  }
  return true;
}

// prepare_constraints of the tile's 8 fluid particles: count_contacts lane by lane (no lists:
// the tile's lists hold fluid only, its SDF sample), density_part 8 lanes at once (nothing kept
// in pair_w: solve_tile recomputes it, see vorticity_tile), then finish_density.
bool density_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  int nc[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) nc[l] = count_contacts(S, s0 + l, S.sp, Lanes{});
  const float inv_rho0 = 1.f / S.c.rest_density;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0);
  vf rho(W.poly6(0.f)), sum2(0.f);
  v3 gi{};
  tile_pairs(
      S, t, [&](const int* j, simd::vm in, auto masked) __attribute__((always_inline)) {
        constexpr bool kMasked = decltype(masked)::value;
        v3 q;
        vf ph;
        gather_packed(S.spk, j, q, ph);
        const auto d = density_pair<vf>(W, inv_rho0, p - q);
        if constexpr (kMasked) {
          rho = select(in, rho + d.wgt, rho);
          sum2 = select(in, sum2 + length2(d.grad), sum2);
        } else {
          rho = rho + d.wgt;
          sum2 = sum2 + length2(d.grad);
        }
        tile_add<kMasked>(gi, d.grad, in);
      });
  for (int l = 0; l < simd::kWidth; ++l)
    finish_density(S, s0 + l, nc[l], DensitySum{rho[l], sum2[l], simd::lane(gi, l)});
  return true;
}

// solve_contacts_fluid of the tile's 8 fluid particles: pbf_part 8 lanes at once, the pairs'
// kernel values from the positions (density_tile kept none), the contact part lane by lane
// (without solid or static neighbours only the scene SDF's contact). Takes the tiles that
// density_tile takes (particles that do not move keep their position here, as in the scalar loop).
bool solve_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0);
  vf li;
  for (int l = 0; l < simd::kWidth; ++l) li.v[l] = S.lambda[s0 + l];
  v3 f{};
  tile_pairs(
      S, t, [&](const int* j, simd::vm in, auto masked) __attribute__((always_inline)) {
        constexpr bool kMasked = decltype(masked)::value;
        v3 q;
        vf lj;
        gather_packed(S.spl, j, q, lj);
        const v3 r = p - q;
        const v3 grad = pair_grad(W, r);
        const vf wgt = W.poly6(length2(r));  // (s_corr off: unused, see pbf_factor)
        tile_add<kMasked>(f, grad * pbf_factor(S.c, wgt, li, lj), in);
      });
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    if (!(S.sw[s] > 0.f)) S.tmp[s] = S.sp[s];
    else
      finish_solve(S, s, SolveSum{contact_part(S, s, S.sp, S.sx, ContactPass::kSolve, Lanes{}), simd::lane(f, l)}, true,
                   false);
  }
  return true;
}

// velocity_effects' second pass for the tile's 8 fluid particles: fluid_forces 8 lanes at once,
// the pairs' kernel values from the positions (vorticity_tile kept none).
bool forces_tile(const SimViews& S, int s0) {
  Tile t;
  if (!fluid_tile(S, s0, t)) return false;
  using simd::v3;
  using simd::vf;
  const float inv_rho0 = 1.f / S.c.rest_density, two_rho0 = 2.f * S.c.rest_density;
  const float coh_c = -S.c.cohesion * inv_rho0, st = -S.c.surface_tension;
  const SphKernel W = S.c.W;
  const v3 p = simd::load_v3(S.sp + s0), ni = simd::load_v3(S.cnormal + s0);
  vf rho_i;
  for (int l = 0; l < simd::kWidth; ++l) rho_i.v[l] = S.density[s0 + l];
  v3 eta{}, acc{};
  tile_pairs(
      S, t, [&](const int* j, simd::vm in, auto masked) __attribute__((always_inline)) {
        constexpr bool kMasked = decltype(masked)::value;
        v3 q, nj;
        vf rho_j, wj;
        gather_packed(S.spd, j, q, rho_j);
        gather_packed(S.cnv, j, nj, wj);
        const v3 r = p - q;
        const v3 grad = pair_grad(W, r);
        const vf cf = pair_cohesion(W, coh_c, r);
        v3 e, a;
        force_pair(inv_rho0, two_rho0, st, r, grad, cf, ni, nj, wj, rho_i, rho_j, e, a);
        tile_add<kMasked>(eta, e, in);
        tile_add<kMasked>(acc, a, in);
      });
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l;
    S.vtmp[s] = fluid_velocity(S, s, finish_forces(S, s, ForceSum{simd::lane(eta, l), simd::lane(acc, l)}));
  }
  return true;
}

// The entries of the runs [run[2 r], run[2 r + 1]) of s, in order, 8 at a time (runs joined in
// a buffer): the distance test of scan_candidates on 8 lanes (s itself rejected), then the kept
// ones left-packed and stored at slot cnt (simd::kPack), or where the 8 could reach the cap each
// candidate stored at slot min(cnt, cap) and counted where it passed (scan_candidates'
// branch-free store). Returns the count.
int scan_candidates_simd(const SimViews& S, vec3 p, float R2, int s, const int* run, int nruns, int* list, int cap) {
  constexpr int kBuf = 128;
  int buf[kBuf + 2 * simd::kWidth];
  const simd::v3 pv = simd::broadcast(p);
  simd::i8 self{}, iota{0, 1, 2, 3, 4, 5, 6, 7};
  self += s;
  int cnt = 0;
  // Tests the first nb (a multiple of kWidth) entries of buf.
  auto test = [&](int nb) {
    for (int b = 0; b < nb; b += simd::kWidth) {
      const int* j = buf + b;
      simd::i8 jv;
      std::memcpy(&jv, j, sizeof jv);
      simd::v3 q;
      simd::vf w;
      gather_packed(S.spk, j, q, w);
      const simd::vm ok = (length2(pv - q) < simd::vf(R2)) & simd::vm{jv != self};
      const int m = simd::bits(ok);
      if (cnt + simd::kWidth <= cap) {
        const simd::i8 kept = simd::permute(jv, simd::pack_lanes(m));
        std::memcpy(list + cnt, &kept, sizeof kept);
        cnt += simd::kPack.count[m];
      } else {
        for (int l = 0; l < simd::kWidth; ++l) {
          list[cnt < cap ? cnt : cap] = j[l];
          cnt += m >> l & 1;
        }
      }
    }
  };
  int nb = 0;
  for (int r = 0; r < nruns; ++r) {
    for (int a = run[2 * r], e = run[2 * r + 1]; a < e;) {
      const int take = e - a < kBuf - nb ? e - a : kBuf - nb;
      simd::i8 v = iota + a;
      for (int k = 0; k < take; k += simd::kWidth, v += simd::kWidth) std::memcpy(buf + nb + k, &v, sizeof v);
      nb += take, a += take;
      if (nb >= kBuf - simd::kWidth) {  // test the full groups, keep the rest
        const int full = nb & ~(simd::kWidth - 1);
        test(full);
        for (int k = full; k < nb; ++k) buf[k - full] = buf[k];
        nb -= full;
      }
    }
  }
  for (int l = 0; l < simd::kWidth; ++l) buf[nb + l] = s;  // padding: rejected as s itself
  test((nb + simd::kWidth - 1) & ~(simd::kWidth - 1));
  return cnt;
}

// find_neighbors' candidates of a particle s at p without the rigid/cloth test on the CPU's SIMD
// lanes: the runs of for_each_run_in_radius (the same rows, row_cells on 8 rows at once, then the
// runs in its order), then their entries 8 at a time (scan_candidates_simd); the same list as
// scan_candidates. Returns the count.
int scan_runs_simd(const SimViews& S, vec3 p, float R, int s, int* list, int cap) {
  constexpr int kReach = GridSpec::reach, kW = 2 * kReach + 1, kRows = kW * kW;
  constexpr int kVecs = (kRows + simd::kWidth - 1) / simd::kWidth;
  const GridSpec& g = S.grid;
  const int3 c = g.cell_of(p);
  const float R2 = R * R, pad = 1e-3f * g.cell;
  const std::uint32_t m = (1u << g.bits) - 1u;
  float ey2[kW], ez2[kW];
  slab_gaps2(g, p, c, pad, ey2, ez2);
  // Row r = dz kW + dy; lanes past the rows get R2 (no row).
  alignas(32) float d2[kVecs * simd::kWidth];
  for (int r = 0; r < kVecs * simd::kWidth; ++r) d2[r] = r < kRows ? ey2[r % kW] + ez2[r / kW] : R2;
  alignas(32) int lo[kVecs * simd::kWidth], hi[kVecs * simd::kWidth];
  for (int v = 0; v < kVecs; ++v) {
    simd::vf dv;
    std::memcpy(&dv.v, d2 + v * simd::kWidth, sizeof dv.v);
    simd::vi a, b;
    row_cells(g, simd::vf(p.x), simd::vi(c.x), R2, pad, dv, a, b);
    std::memcpy(lo + v * simd::kWidth, &a.v, sizeof a.v);
    std::memcpy(hi + v * simd::kWidth, &b.v, sizeof b.v);
  }
  int run[4 * kRows];
  int nr = 0;
  const int* start = S.cell_start;
  for (int dz = 0; dz < kW; ++dz) {
    const std::uint32_t slab = (static_cast<std::uint32_t>(c.z + dz - kReach) & m) << (2 * g.bits);
    for (int dy = 0; dy < kW; ++dy) {
      const int r = dz * kW + dy;
      if (d2[r] >= R2) continue;
      const std::uint32_t row = ((static_cast<std::uint32_t>(c.y + dy - kReach) & m) << g.bits) | slab;
      const std::uint32_t x0 = static_cast<std::uint32_t>(lo[r]) & m, x1 = static_cast<std::uint32_t>(hi[r]) & m;
      if (x0 <= x1) {
        run[nr] = start[row | x0], run[nr + 1] = start[(row | x1) + 1];
        nr += 2;
      } else {  // the x range wraps: [x0, m] and [0, x1]
        run[nr] = start[row | x0], run[nr + 1] = start[(row | m) + 1];
        run[nr + 2] = start[row], run[nr + 3] = start[(row | x1) + 1];
        nr += 4;
      }
    }
  }
  return scan_candidates_simd(S, p, R2, s, run, nr / 2, list, cap);
}

// find_neighbors of the tile's 8 particles, one per lane, where none of them needs the
// rigid/cloth test, the scene has no static particles, and all 8 share their cell's y and z
// (consecutive sorted particles along a row of cells) within a few cells along x: the rows of
// cells (for_each_run_in_radius) once for the tile, each row's x range the union of the lanes'
// ranges, and each candidate tested against the 8 particles at once. The union holds every
// lane's own candidates in its own order (the same rows in the same order, x ascending within a
// row, wrapping at the same place: the union spans fewer cells than the grid) and only
// candidates that fail its distance test besides (outside a lane's padded rows and ranges), so
// each lane's list is the one scan_candidates makes. Then each lane's kept candidates are
// left-packed into its list (simd::kPack) and find_neighbors' epilogue runs.
bool neighbors_tile(const SimViews& S, int s0) {
  constexpr int kReach = GridSpec::reach, kW = 2 * kReach + 1, kSpan = 8, kBlock = 256;
  if (s0 + simd::kWidth > S.n || S.ns > 0 || S.nbr_col != 1) return false;  // (the CPU's lists are rows)
  for (int l = 0; l < simd::kWidth; ++l)
    if (phase::is(S.sphase[s0 + l], phase::kRigid | phase::kCloth)) return false;
  using simd::vf;
  using simd::vi;
  const GridSpec& g = S.grid;
  const float R = S.c.search_radius, R2 = R * R, pad = 1e-3f * g.cell;
  const simd::v3 p = simd::load_v3(S.sp + s0);
  const vi cx = floor_int(p.x * g.inv_cell), cy = floor_int(p.y * g.inv_cell), cz = floor_int(p.z * g.inv_cell);
  int xmin = cx[0], xmax = cx[0];
  for (int l = 0; l < simd::kWidth; ++l) {
    if (cy[l] != cy[0] || cz[l] != cz[0]) return false;
    xmin = cx[l] < xmin ? cx[l] : xmin, xmax = cx[l] > xmax ? cx[l] : xmax;
  }
  if (xmax - xmin > kSpan) return false;
  const int m = (1 << g.bits) - 1;
  vf ey2[kW], ez2[kW];
  for (int d = 0; d < kW; ++d) {
    const vf ey = slab_gap(p.y, cy[0] + d - kReach, g.cell, pad), ez = slab_gap(p.z, cz[0] + d - kReach, g.cell, pad);
    ey2[d] = ey * ey, ez2[d] = ez * ez;
  }
  // The runs of the rows' unions, in for_each_run_in_radius' order.
  int ra[2 * kW * kW], re[2 * kW * kW], nr = 0;
  for (int dz = 0; dz < kW; ++dz) {
    const int slab = ((cz[0] + dz - kReach) & m) << (2 * g.bits);
    for (int dy = 0; dy < kW; ++dy) {
      const vf d2 = ey2[dy] + ez2[dz];
      const simd::vm in = d2 < vf(R2);
      const int rows = simd::bits(in);
      if (rows == 0) continue;
      vi lo, hi;
      row_cells(g, p.x, cx, R2, pad, d2, lo, hi);
      int u0 = 1 << 30, u1 = -(1 << 30);
      for (int l = 0; l < simd::kWidth; ++l) {
        if (!(rows >> l & 1)) continue;
        u0 = lo[l] < u0 ? lo[l] : u0, u1 = hi[l] > u1 ? hi[l] : u1;
      }
      const int row = (((cy[0] + dy - kReach) & m) << g.bits) | slab;
      const int x0 = u0 & m, x1 = u1 & m;
      if (x0 <= x1) {
        ra[nr] = S.cell_start[row | x0], re[nr++] = S.cell_start[(row | x1) + 1];
      } else {  // the x range wraps: [x0, m] and [0, x1]
        ra[nr] = S.cell_start[row | x0], re[nr++] = S.cell_start[(row | m) + 1];
        ra[nr] = S.cell_start[row], re[nr++] = S.cell_start[(row | x1) + 1];
      }
    }
  }
  // Candidates in blocks: each one's lane mask (bit l: kept by lane l), then the lanes' lists.
  alignas(32) int cand[kBlock + 32];
  alignas(32) std::uint8_t keep[kBlock + 32];
  int* list[simd::kWidth];
  int cnt[simd::kWidth];
  for (int l = 0; l < simd::kWidth; ++l) list[l] = S.nbr + (s0 + l) * S.nbr_row, cnt[l] = 0;
  const int cap = S.c.max_neighbors;
  int nc = 0;
  auto flush = [&]() {
    for (int k = nc; k < nc + 32; ++k) cand[k] = 0, keep[k] = 0;
    for (int l = 0; l < simd::kWidth; ++l) {
      int c = cnt[l];
      for (int k = 0; k < nc; k += 32) {
        const unsigned b32 = simd::byte_bits(keep + k, l);
        for (int q = 0; q < 32 && k + q < nc; q += simd::kWidth) {
          const int b = static_cast<int>(b32 >> q & 0xFFu);
          if (c + simd::kWidth <= cap) {
            simd::i8 j;
            std::memcpy(&j, cand + k + q, sizeof j);
            const simd::i8 kept = simd::permute(j, simd::pack_lanes(b));
            std::memcpy(list[l] + c, &kept, sizeof kept);
            c += simd::kPack.count[b];
          } else {
            for (int i = 0; i < simd::kWidth; ++i) {
              list[l][c < cap ? c : cap] = cand[k + q + i];
              c += b >> i & 1;
            }
          }
        }
      }
      cnt[l] = c;
    }
    nc = 0;
  };
  const Packed* const spk = S.spk;
  std::uint32_t all = ~0u;  // the phase bits that every candidate has
  for (int r = 0; r < nr; ++r) {
    for (int j = ra[r], e = re[r]; j < e; ++j) {
      const Packed q = spk[j];
      all &= q.bits();
      const simd::v3 d = p - simd::broadcast(q.xyz());
      const unsigned own = static_cast<unsigned>(j - s0);  // a lane's own particle: not kept
      const unsigned b = static_cast<unsigned>(simd::bits(length2(d) < vf(R2))) & (own < 8u ? ~(1u << own) : ~0u);
      cand[nc] = j, keep[nc] = static_cast<std::uint8_t>(b);
      if (++nc == kBlock) flush();
    }
  }
  flush();
  for (int l = 0; l < simd::kWidth; ++l) {
    const int s = s0 + l, stored = cnt[l] < cap ? cnt[l] : cap;
    int solid = stored;
    if (phase::is(S.sphase[s], phase::kFluid)) {
      solid = 0;
      if (!phase::is(all, phase::kFluid))  // (otherwise every candidate is fluid)
        for (int k = 0; k < stored; ++k) solid += !phase::is(spk[list[l][k]].bits(), phase::kFluid);
    }
    finish_neighbors(S, s, cnt[l], solid, 0);
  }
  return true;
}
}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
