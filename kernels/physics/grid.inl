// Kernel bodies of physics/grid.hpp: prediction, the cell sort and the neighbour lists.
#pragma once
#include "kernels/physics/cpu_tiles.hpp"
#include "kernels/physics/grid.hpp"
#include "kernels/physics/pair_math.hpp"

namespace seamless::kernels {

template <Executor Exec> void NeighbourGrid<Exec>::predict(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t i) {
    vec3 v = S.v[i];
    if (S.w[i] > 0.f) v = v + S.c.gravity * S.c.dt;
    float l2 = length2(v);
    if (l2 > S.c.max_speed * S.c.max_speed) v = v * (S.c.max_speed / sqrtf(l2));
    vec3 p = S.x[i] + v * S.c.dt;
    S.v[i] = v;
    S.pred[i] = p;
    S.key[i] = S.grid.key(S.grid.cell_of(p));
    S.order[i] = static_cast<int>(i);
    if (i == 0) S.counters[4] = 0;  // largest |v|^2 of this substep, found by write_back
  });
}

template <Executor Exec>
void NeighbourGrid<Exec>::sort_cells(const Exec& ex, std::uint32_t* keys, int* values, std::int64_t n, int bits) {
  ex.sort_by_key(keys, values, n, bits);
}

template <Executor Exec>
std::size_t NeighbourGrid<Exec>::sort_cells_temp_bytes(const Exec& ex, std::int64_t n, int bits) {
  return ex.template sort_by_key_temp_bytes<std::uint32_t, int>(n, bits);
}

// Gathers the slot state into the sorted order; order[s] becomes the particle id of sorted index
// s (each thread rewrites only its own entry) and rank its inverse.
template <Executor Exec> void NeighbourGrid<Exec>::reorder(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    const int slot = S.order[s], id = S.slot_id[slot];
    S.order[s] = id;
    S.rank[id] = static_cast<int>(s);
    S.sx[s] = S.x[slot];
    S.sp[s] = S.pred[slot];
    S.sp0[s] = S.pred[slot];
    S.sv[s] = S.v[slot];
    S.sw[s] = S.w[slot];
    S.sphase[s] = S.phase[slot];
    S.spk[s] = Packed::of_phase(S.pred[slot], S.phase[slot]);  // for find_neighbors
  });
}

template <Executor Exec>
void NeighbourGrid<Exec>::cell_starts(const Exec& ex, const std::uint32_t* keys, std::int64_t n, int* start,
                                      std::int64_t cells) {
  // Each task fills a block of cells: one binary search for the first, then a merge walk along
  // the sorted keys (work per task: the block's cells plus the entries in them). Parallel on both
  // backends, no atomics, no host sync, and no task fills a long run of empty cells alone. Blocks
  // of 32 cells on the CPU, where a thread's binary search is shared by many cells; of 4 on CUDA,
  // where the walk is a chain of dependent loads and stores: with 32, 10k particles' 2^18 cells
  // made 33 blocks of threads that each waited on 32 of them (most multiprocessors idle), with 4
  // it is 256 blocks of 4 (the binary searches' upper levels are
  // shared in cache).
  //
  // The CPU instead gives each entry i the cells (keys[i - 1], keys[i]] (entry 0 those up to
  // keys[0], entry n those after the last key) and stores i there: the cells of a task are one
  // run, which the compiler stores 4 at a time, and every cell is written once by one task. Most
  // cells are empty (2^18 cells for 10k particles), so this is ~0.3 instructions a cell instead
  // of a compare and a store (4.7 M of a 10k fluid step). Not on CUDA: one thread would fill a
  // long empty run alone. The same values either way (start[k] = number of keys below k).
  if constexpr (Exec::device == Device::CPU) {
    ex.for_each(n + 1, [=] SEAMLESS_HD(std::int64_t i) {
      const std::int64_t lo = i == 0 ? 0 : static_cast<std::int64_t>(keys[i - 1]) + 1;
      const std::int64_t hi = i == n ? cells : static_cast<std::int64_t>(keys[i]);  // inclusive
      for (std::int64_t k = lo; k <= hi; ++k) start[k] = static_cast<int>(i);
    });
    return;
  }
  constexpr std::int64_t kBlock = Exec::device == Device::CUDA ? 4 : 32;
  const std::int64_t total = cells + 1;
  ex.for_each((total + kBlock - 1) / kBlock, [=] SEAMLESS_HD(std::int64_t b) {
    const std::int64_t k0 = b * kBlock, k1 = k0 + kBlock < total ? k0 + kBlock : total;
    int pos = lower_bound_key(keys, static_cast<int>(n), static_cast<std::uint32_t>(k0));
    for (std::int64_t k = k0; k < k1; ++k) {
      while (pos < n && keys[pos] < static_cast<std::uint32_t>(k)) ++pos;
      start[k] = pos;
    }
  });
}

template <Executor Exec>
void NeighbourGrid<Exec>::cell_keys(const Exec& ex, const vec3* p, std::int64_t n, GridSpec g, std::uint32_t* keys,
                                    int* idx) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    keys[i] = g.key(g.cell_of(p[i]));
    idx[i] = static_cast<int>(i);
  });
}

template <Executor Exec>
void NeighbourGrid<Exec>::gather_vec3(const Exec& ex, const vec3* src, const int* idx, std::int64_t n, vec3* dst) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) { dst[i] = src[idx[i]]; });
}

namespace detail {
// Appends the candidates [a, e) of s that pass keep(j) to list (stride col, cap entries and a
// spare slot at cap), the lanes of g taking every g.size-th candidate and Lanes::rank placing
// them, so the list keeps the candidates' order whatever the lane count. Branch-free: about half
// the candidates fail the distance test at random, which a branch mispredicts; a rejected one is
// written to the spare slot, which nothing reads. cnt counts every accepted candidate (also past
// the cap); kept(j) is called for those stored.
template <class Keep, class Kept>
SEAMLESS_HD inline void append_run(int a, int e, Lanes g, int* list, std::int64_t col, int cap, int& cnt, Keep&& keep,
                                   Kept&& kept) {
  for (int b = a; b < e; b += g.size) {  // the same trip count in every lane of the group
    const bool in = b + g.lane < e;
    const int j = in ? b + g.lane : a;  // lanes past the run look at a valid entry, and reject it
    const bool ok = in & keep(j);
    int found = 0;
    const int slot = cnt + g.rank(ok, &found);
    const bool store = ok & (slot < cap);
    list[(store ? slot : cap) * col] = j;
    kept(j, store);
    cnt += found;
  }
}

// The CPU's candidate loop over the entries [a, e) of a run, none of them s (find_neighbors):
// every candidate is written to its slot (list row-major, col = 1 on the CPU), where the next
// one overwrites it unless it was kept: about half the candidates fail the distance test at
// random, which a branch mispredicts (the slot past the last kept entry, like the spare one at
// cap, is never read). Clamp: whether the slot must be clamped to the spare one (only where the
// run can reach the cap). General: the rigid/cloth pair test (may_interact). Everything in
// locals, so that the stores to list cannot make the compiler reload s, cap or the count.
// Returns the count.
template <bool General, bool Clamp>
SEAMLESS_HD inline int scan_candidates(const SimViews& S, vec3 p, float R2, std::uint32_t ph, int s, int a, int e,
                                       int* list, int cap, int c) {
  const Packed* const spk = S.spk;
  for (int j = a; j < e; ++j) {
    const Packed q = spk[j];  // position and phase in one load
    bool ok = length2(p - q.xyz()) < R2;
    if constexpr (General) ok = ok && may_interact(S, ph, q.bits(), s, j);
    list[Clamp ? (c < cap ? c : cap) : c] = j;
    c += ok;
  }
  return c;
}

// CUDA's candidate loop for a lane that walks its runs alone (find_neighbors): the candidates
// [a, e) of s, 4 at a time, all 4 loaded before any is tested (lanes past the run load its last
// entry and reject it): 4 loads in flight instead of one chain of load-test-store per candidate
// (see for_each_entry; 2 or 8 at a time were slower). Only kept candidates are stored: a store
// for every candidate (the CPU's branch-free way) costs memory traffic that the diverging
// threads of a warp cannot coalesce. They are stored through a pointer that moves one column per
// stored candidate: indexing the column-major list by count x column took 64-bit multiplies and
// a branch per candidate (docs/PERFORMANCE.md has the measurements).
// General: the rigid/cloth pair test (may_interact), compiled only into the walk of rigid and
// cloth particles (a runtime test per candidate left its loads if-converted into the fluid
// walk, 7 % of the instructions). cnt counts every accepted candidate, solid those stored
// without a bit of solid_mask.
template <bool General>
SEAMLESS_HD inline void scan_run_lane(const SimViews& S, vec3 p, float R2, std::uint32_t ph, int s,
                                      std::uint32_t solid_mask, int a, int e, int* list, int cap, int& cnt,
                                      int& solid) {
  const int col = static_cast<int>(S.nbr_col);  // particle count on CUDA (< 2^31)
  int c = cnt, so = solid;
  int* out = list + static_cast<std::int64_t>(c < cap ? c : cap) * col;
  for (int b = a; b < e; b += 4) {
    Packed q[4];
    SEAMLESS_PHYS_UNROLL
    for (int u = 0; u < 4; ++u) q[u] = S.spk[b + u < e ? b + u : e - 1];  // position and phase
    SEAMLESS_PHYS_UNROLL
    for (int u = 0; u < 4; ++u) {
      const int j = b + u;
      const std::uint32_t phj = q[u].bits();
      bool ok = (j < e) & (j != s) & (length2(p - q[u].xyz()) < R2);
      if constexpr (General) ok = ok && may_interact(S, ph, phj, s, j);
      const bool store = ok & (c < cap);
      so += store & ((phj & solid_mask) == 0u);
      if (store) *out = j;
      out += store ? col : 0;
      c += ok;
    }
  }
  cnt = c, solid = so;
}

// s's list lengths (cnt candidates kept, solid of them not fluid, scnt static ones) and the
// overflow counters.
SEAMLESS_HD inline void finish_neighbors(const SimViews& S, int s, int cnt, int solid, int scnt) {
  if (cnt > S.c.max_neighbors) atomic_add(&S.counters[0], 1);
  // Read first: the shared maximum rarely changes, so most particles only load it.
  if (cnt > atomic_load(&S.counters[2])) atomic_max(&S.counters[2], cnt);
  S.nnbr[s] = cnt < S.c.max_neighbors ? cnt : S.c.max_neighbors;
  S.nsolid[s] = solid;
  if (S.ns > 0) {
    if (scnt > S.c.max_static_neighbors) atomic_add(&S.counters[1], 1);
    if (scnt > atomic_load(&S.counters[3])) atomic_max(&S.counters[3], scnt);
  }
  S.nsnbr[s] = scnt < S.c.max_static_neighbors ? scnt : S.c.max_static_neighbors;
}
}  // namespace detail

template <Executor Exec> void NeighbourGrid<Exec>::find_neighbors(const Exec& ex, const SimViews& S) {
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    // A CPU thread walks a particle's runs alone (Lanes{}); CUDA does from about 270k particles.
    // (Declared here: an extended CUDA lambda cannot capture what an if constexpr tests.)
    constexpr bool kOneLane = Exec::device == Device::CPU;
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    const float R = S.c.search_radius, R2 = R * R;
    const std::uint32_t ph = S.sphase[s];
    // Only rigid and cloth particles skip pairs (may_interact); a fluid particle counts the
    // entries that are not fluid (both_fluid), anything else every stored entry.
    const bool plain = !phase::is(ph, phase::kRigid | phase::kCloth), sfluid = phase::is(ph, phase::kFluid);
    const int cap = S.c.max_neighbors;
    int* const list = S.nbr + s * S.nbr_row;
    int cnt = 0, solid = 0;
    if constexpr (kOneLane) {
      // The CPU: the same entries in the same order as append_run with one lane, in a loop of
      // its own (counts in registers, one load per candidate, the rigid/cloth test only for
      // rigid and cloth particles, branch-free store); the non-fluid entries of a fluid
      // particle are counted afterwards over the ~30 stored entries instead of the ~70
      // candidates.
      auto walk = [&](auto general) {
        constexpr bool kGeneral = decltype(general)::value;
        for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
          // s itself sits in one run (its own row): the run is split around it instead of
          // testing j != s for every candidate. Where the run cannot reach the cap, the slot
          // needs no clamp.
          const bool self = a <= s && s < e;
          if (cnt + (e - a) <= cap) {
            if (self)
              cnt = detail::scan_candidates<kGeneral, false>(
                  S, p, R2, ph, s, s + 1, e, list, cap,
                  detail::scan_candidates<kGeneral, false>(S, p, R2, ph, s, a, s, list, cap, cnt));
            else cnt = detail::scan_candidates<kGeneral, false>(S, p, R2, ph, s, a, e, list, cap, cnt);
          } else {
            if (self)
              cnt = detail::scan_candidates<kGeneral, true>(
                  S, p, R2, ph, s, s + 1, e, list, cap,
                  detail::scan_candidates<kGeneral, true>(S, p, R2, ph, s, a, s, list, cap, cnt));
            else cnt = detail::scan_candidates<kGeneral, true>(S, p, R2, ph, s, a, e, list, cap, cnt);
          }
        });
      };
#if !defined(__CUDACC__)
      if (plain && simd::cpu_simd()) cnt = detail::scan_runs_simd(S, p, R, s, list, cap);
      else
#endif
          if (plain)
        walk(std::false_type{});
      else walk(std::true_type{});
      const int stored = cnt < cap ? cnt : cap;
      if (!sfluid) solid = stored;
      else
        for (int k = 0; k < stored; ++k) solid += !phase::is(S.spk[list[k * S.nbr_col]].bits(), phase::kFluid);
    } else if (g.size == 1) {  // (if constexpr ... else if: the CUDA instantiation)
      // CUDA, one lane: as above (the rigid/cloth test compiled only into the walk of rigid and
      // cloth particles), the non-fluid entries counted on the way (the phase is loaded anyway)
      // and only kept candidates stored.
      const std::uint32_t solid_mask = sfluid ? phase::kFluid : 0u;  // stored entries without these bits count
      auto walk = [&](auto general) {
        for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
          detail::scan_run_lane<decltype(general)::value>(S, p, R2, ph, s, solid_mask, a, e, list, cap, cnt, solid);
        });
      };
      if (plain) walk(std::false_type{});
      else walk(std::true_type{});
    } else {
      for_each_run_in_radius(S.grid, S.cell_start, p, R, [&](int a, int e) {
        detail::append_run(
            a, e, g, list, S.nbr_col, cap, cnt,
            [&](int j) {
              const Packed q = S.spk[j];
              return (j != s) & (length2(p - q.xyz()) < R2) & detail::may_interact(S, ph, q.bits(), s, j);
            },
            [&](int j, bool stored) { solid += stored & !detail::both_fluid(ph, S.spk[j].bits()); });
      });
    }
    int scnt = 0;
    if (S.ns > 0) {
      for_each_run_in_radius(S.sgrid, S.scell_start, p, R, [&](int a, int e) {
        detail::append_run(
            a, e, g, S.snbr + s * S.snbr_row, S.snbr_col, S.c.max_static_neighbors, scnt,
            [&](int j) { return length2(p - S.stat[j]) < R2; }, [](int, bool) {});
      });
    }
    solid = g.sum(solid);
    if (g.lane != 0) return;
    detail::finish_neighbors(S, s, cnt, solid, scnt);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::neighbors_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kSearchLanes, one);
}

}  // namespace seamless::kernels
