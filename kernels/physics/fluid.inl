// Kernel bodies of physics/fluid.hpp: the PBF density constraint with the contacts of the same
// pass, and the fluid's velocity effects (viscosity, vorticity, cohesion, surface tension, cloth
// aerodynamics).
#pragma once
#include "kernels/physics/contacts.inl"
#include "kernels/physics/cpu_tiles.hpp"
#include "kernels/physics/fluid.hpp"

namespace seamless::kernels {

// Density (PBF eq. 2, number density: rho_i = sum_j W_ij, solid neighbours weighted by
// solid_density_scale, Macklin 2014 section 7.1), constraint C_i = rho_i / rho_0 - 1 (eq. 1,
// clamped to C_i >= 0 when unilateral) and lambda_i = -C_i / (sum_k |grad_k C_i|^2 + eps)
// (eqs. 8-11). Only fluid particles are moved by the density constraint.
namespace detail {
// One lane's share of the density sums of fluid particle s (prepare_constraints).
struct DensitySum {
  float rho, sum2;
  vec3 gi;
};
SEAMLESS_HD inline DensitySum operator+(const DensitySum& a, const DensitySum& b) {
  return {a.rho + b.rho, a.sum2 + b.sum2, a.gi + b.gi};
}

// One pair's kernel values for r = p_i - p_j (poly6 wgt, spiky gradient gw) and grad_j C_i =
// gw / rho_0; F is float or the CPU's SIMD lanes (V their vec3).
template <class F, class V> struct DensityPair {
  V gw, grad;
  F wgt;
};
template <class F, class V> SEAMLESS_HD inline DensityPair<F, V> density_pair(const SphKernel& W, float inv_rho0, V r) {
  DensityPair<F, V> d;
  d.wgt = W.poly6(length2(r));
  d.gw = pair_grad(W, r);
  d.grad = d.gw * inv_rho0;
  return d;
}

// Lane g's share of rho_i (starting from W(0) in lane 0), sum_j |grad_j C_i|^2 and grad_i C_i;
// with Cache, each pair's kernel values are kept in pair_w for pbf_part.
template <bool Cache> SEAMLESS_HD inline DensitySum density_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float inv_rho0 = 1.f / S.c.rest_density, sw = S.c.solid_density_scale;
  DensitySum d{g.lane == 0 ? S.c.W.poly6(0.f) : 0.f, 0.f, {0.f, 0.f, 0.f}};
  const bool mixed = S.nsolid[s] != 0;  // otherwise every neighbour is fluid: no phase loads
  // Local copies: the stores to pair_w (floats) could otherwise alias the kernel constants in S,
  // which the compiler would then reload for every pair.
  const SphKernel W = S.c.W;
  const int* const list = S.nbrs(s);
  Packed* const cache = S.pair_w + s * S.nbr_row;
  const std::int64_t col = S.nbr_col;
  const auto gather = [&](int j) { return S.spk[j]; };  // position and phase in one load
  for_each_entry<kPairBatch1>(list, col, S.nnbr[s], g, gather, [&](int k, const Packed& q) {
    const DensityPair<float, vec3> dp = density_pair<float>(W, inv_rho0, p - q.xyz());
    if constexpr (Cache) cache[k * col] = Packed::of(dp.gw, dp.wgt);
    // A solid neighbour's terms are scaled by sw and add nothing to sum2 (selects, not branches:
    // for_each_entry; x 1 and + 0 leave a fluid pair's sums bit for bit as they were).
    const bool fluid = !mixed || phase::is(q.bits(), phase::kFluid);
    const float f = fluid ? 1.f : sw;
    d.rho += f * dp.wgt;
    d.gi += dp.grad * f;
    d.sum2 += fluid ? length2(dp.grad) : 0.f;
  });
  for (int k = g.lane, m = S.nsnbr[s]; k < m; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    d.rho += sw * S.c.W.poly6(length2(r));
    d.gi += S.c.W.spiky_grad(r) * (sw * inv_rho0);
  }
  return d;
}

// Fluid particle s's constraint from its sums d and its contact count nc.
SEAMLESS_HD inline void finish_density(const SimViews& S, int s, int nc, const DensitySum& d) {
  S.ncontacts[s] = nc;
  float C = d.rho * (1.f / S.c.rest_density) - 1.f;
  if (S.c.unilateral && C < 0.f) C = 0.f;
  const float lambda = -C / (d.sum2 + length2(d.gi) + S.c.relaxation);
  S.lambda[s] = lambda;
  S.spl[s] = Packed::of(S.sp[s], lambda);  // what solve_contacts_fluid gathers of a neighbour
  S.density[s] = d.rho;
  S.h_rho[s] = S.c.h / d.rho;  // once here instead of once per neighbour pair in velocity_effects
}
}  // namespace detail

template <Executor Exec> void Fluid<Exec>::prepare_constraints(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_contacts[b] = 0; });
  detail::pack_positions(ex, S);
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const int nc = detail::count_contacts(S, s, S.sp, g);
    if (!phase::is(S.sphase[s], phase::kFluid)) {
      if (g.lane != 0) return;
      S.ncontacts[s] = nc;
      S.lambda[s] = 0.f;
      S.spl[s] = Packed::of(S.sp[s], 0.f);
      S.density[s] = S.c.rest_density;
      S.h_rho[s] = S.c.h / S.c.rest_density;
      return;
    }
    const detail::DensitySum d = g.sum(detail::density_part<detail::kCachePairs<Exec>>(S, s, g));
    if (g.lane != 0) return;
    detail::finish_density(S, s, nc, d);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::density_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

namespace detail {
// Lane g's share of the contact corrections (acc) and of the PBF sum (f) of s.
struct SolveSum {
  vec3 acc, f;
};
SEAMLESS_HD inline SolveSum operator+(const SolveSum& a, const SolveSum& b) { return {a.acc + b.acc, a.f + b.f}; }

// One fluid pair's term of the PBF sum is grad times this factor, lambda_i + lambda_j + s_corr,
// s_corr from the pair's poly6 wgt (eq. 13, n = 4); F is float or the CPU's SIMD lanes.
// Without a branch: with s_corr off (scorr_k = 0), sc is -0 and li + lj + sc is li + lj to the bit.
template <class F> SEAMLESS_HD inline F pbf_factor(const SimConstants& c, F wgt, F li, F lj) {
  const F q = wgt * c.scorr_inv_wdq;
  const F sc = -c.scorr_k * q * q * q * q;
  return li + lj + sc;
}

// The PBF position update of fluid particle s (eq. 12) with the artificial pressure s_corr
// (eq. 13, n = 4), before the division by rho_0: lane g's share. With Cached, the pairs' kernel
// values come from pair_w (prepare_constraints at these positions) instead of the positions.
// Mixed: whether s has neighbours that are not fluid (nsolid); otherwise a loop of its own without
// phase loads (a runtime test left predicated loads and byte moves in every pair; the two loops
// are faster on fluid_1m, docs/PERFORMANCE.md).
template <bool Cached, bool Mixed> SEAMLESS_HD inline vec3 pbf_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float li = S.lambda[s], sw = S.c.solid_density_scale;
  constexpr bool mixed = Mixed;
  vec3 f{0.f, 0.f, 0.f};
  // Position and lambda in one load (Cached: lambda alone), and whether j is fluid.
  const auto gather = [&](int j) {
    const bool fluid = !mixed || phase::is(S.sphase[j], phase::kFluid);
    return Gather1{Cached ? Packed{0.f, 0.f, 0.f, S.lambda[j]} : S.spl[j], fluid};
  };
  for_each_entry<kPairBatch1>(S.nbrs(s), S.nbr_col, S.nnbr[s], g, gather, [&](int k, const Gather1& n) {
    vec3 grad;
    float wgt, lj;
    if constexpr (Cached) {
      const Packed gw = S.pair_w[s * S.nbr_row + k * S.nbr_col];
      grad = gw.xyz(), wgt = gw.w, lj = n.a.w;
    } else {
      const Packed pl = n.a;
      const vec3 r = p - pl.xyz();
      grad = pair_grad(S.c.W, r), lj = pl.w;
      wgt = S.c.W.poly6(length2(r));  // (s_corr off: unused, see pbf_factor)
    }
    f += grad * (n.fluid ? pbf_factor(S.c, wgt, li, lj) : li * sw);  // a solid neighbour: li * sw alone
  });
  for (int k = g.lane, m = S.nsnbr[s]; k < m; k += g.size)
    f += S.c.W.spiky_grad(p - S.stat[S.snbrs(s)[k * S.snbr_col]]) * (li * sw);
  return f;
}

// s's new position from its sums (the contacts' part.acc, the PBF or coupling sum part.f).
SEAMLESS_HD inline void finish_solve(const SimViews& S, int s, const SolveSum& part, bool fluid, bool coupled) {
  vec3 acc = part.acc;
  add_sdf_contact(S, s, S.sp, S.sx, ContactPass::kSolve, acc);
  if (fluid) acc += part.f * (1.f / S.c.rest_density);
  if (coupled) acc += part.f * (S.c.solid_density_scale / S.c.rest_density);
  S.tmp[s] = S.sp[s] + acc;
}

// Two-way coupling of solid particle s: the reaction of the density correction a fluid neighbour
// j received from it (equal and opposite momentum: scaled by w_s / w_j), lane g's share.
SEAMLESS_HD inline vec3 coupling_part(const SimViews& S, int s, Lanes g) {
  const vec3 p = S.sp[s];
  const float ws = S.sw[s];
  vec3 f{0.f, 0.f, 0.f};
  for (int k = g.lane, m = S.nnbr[s]; k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    if (!phase::is(S.sphase[j], phase::kFluid)) continue;
    const Packed pl = S.spl[j];
    f += S.c.W.spiky_grad(p - pl.xyz()) * (pl.w * ws / S.sw[j]);
  }
  return f;
}
}  // namespace detail

template <Executor Exec> void Fluid<Exec>::solve_contacts_fluid(const Exec& ex, const SimViews& S) {
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    if (!(S.sw[s] > 0.f)) {
      if (g.lane == 0) S.tmp[s] = p;
      return;
    }
    const bool fluid = phase::is(S.sphase[s], phase::kFluid), coupled = !fluid && S.c.solid_density_scale > 0.f;
    detail::SolveSum part{detail::contact_part(S, s, S.sp, S.sx, detail::ContactPass::kSolve, g), {0.f, 0.f, 0.f}};
    if (fluid) {
      constexpr bool kCache = detail::kCachePairs<Exec>;
      part.f = S.nsolid[s] != 0 ? detail::pbf_part<kCache, true>(S, s, g) : detail::pbf_part<kCache, false>(S, s, g);
    }
    if (coupled) part.f = detail::coupling_part(S, s, g);
    part = g.sum(part);
    if (g.lane != 0) return;
    detail::finish_solve(S, s, part, fluid, coupled);
  };
#if !defined(__CUDACC__)
  if (!cpu_tiles(ex, S, detail::solve_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

namespace detail {

// Akinci 2013: cohesion (eq. 1) and curvature (eq. 5) accelerations, with the symmetrising
// factor K_ij = 2 rho_0 / (rho_i + rho_j) (eq. 6), and vorticity confinement (PBF eqs. 15-16),
// summed over the lanes of g (in every lane). Masses are volume fractions 1 / rho_0.
struct ForceSum {
  vec3 eta, acc;
};
SEAMLESS_HD inline ForceSum operator+(const ForceSum& a, const ForceSum& b) { return {a.eta + b.eta, a.acc + b.acc}; }

// Akinci's cohesion term of the pair r = p_i - p_j (eq. 1, before K_ij) is r times this factor
// of l = |r| (0 for coincident particles); coh_c = -cohesion / rho_0.
template <class F> SEAMLESS_HD inline F cohesion_factor(const SphKernel& W, float coh_c, F l) {
  return select(l > 1e-9f, coh_c * W.akinci(l) / l, F(0.f));
}

// One fluid pair's terms of ForceSum: r = p_i - p_j, the pair's spiky gradient and cohesion
// factor cf, n_i, n_j, |omega_j| (wj), rho_i, rho_j; F is float or the CPU's SIMD lanes (V their
// vec3).
template <class F, class V>
SEAMLESS_HD inline void force_pair(float inv_rho0, float two_rho0, float st, V r, V grad, F cf, V ni, V nj, F wj,
                                   F rho_i, F rho_j, V& eta, V& acc) {
  eta = grad * (wj * inv_rho0);
  F K = fast_div(two_rho0, rho_i + rho_j);  // __fdividef on CUDA
  V coh = r * cf;
  V curv = (ni - nj) * st;
  acc = (coh + curv) * K;
}

// The fluid force of s from its sums t: t.acc plus vorticity confinement (PBF eqs. 15-16):
// f = eps (N x omega), N = eta / |eta|.
SEAMLESS_HD inline vec3 finish_forces(const SimViews& S, int s, ForceSum t) {
  float el = length(t.eta);
  if (el > 1e-9f && S.c.vorticity > 0.f) t.acc += cross(t.eta / el, S.vort[s]) * S.c.vorticity;
  return t.acc;
}

// The velocity of fluid particle s after viscosity (its XSPH sum in vtmp) and its forces.
SEAMLESS_HD inline vec3 fluid_velocity(const SimViews& S, int s, vec3 forces) {
  return S.sv[s] + (S.vtmp[s] * S.c.viscosity + forces * S.c.dt);
}
// cohesion_factor of |r| (r = p_i - p_j), with one reciprocal square root on CUDA (pair_grad).
template <class V> SEAMLESS_HD inline auto pair_cohesion(const SphKernel& W, float coh_c, V r) {
#if defined(__CUDA_ARCH__)
  const float l2 = length2(r);
  if (!(l2 > 1e-18f)) return 0.f;  // l <= 1e-9, as cohesion_factor
  const float il = rsqrt_normal(l2);
  return coh_c * W.akinci(l2 * il) * il;
#else
  return cohesion_factor(W, coh_c, length(r));
#endif
}

// With Cached, each pair's spiky gradient and cohesion factor come from pair_w (vorticity_part,
// at the same positions) instead of a square root, a division and both kernels.
// Mixed: as pbf_part.
template <bool Cached, bool Mixed> SEAMLESS_HD inline vec3 fluid_forces(const SimViews& S, int s, Lanes g) {
  const float inv_rho0 = 1.f / S.c.rest_density;
  const vec3 p = S.sp[s], ni = S.cnormal[s];
  constexpr bool mixed = Mixed;
  // Locals: nothing here is reloaded for every pair.
  const float two_rho0 = 2.f * S.c.rest_density, rho_i = S.density[s], coh_c = -S.c.cohesion * inv_rho0;
  const float st = -S.c.surface_tension;
  const int* const list = S.nbrs(s);
  const std::int64_t col = S.nbr_col, row = s * S.nbr_row;
  ForceSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}};
  // Position and density, normal and |omega| (cnv is written for fluid particles only).
  const auto gather = [&](int j) {
    const bool fluid = !mixed || phase::is(S.sphase[j], phase::kFluid);
    return Gather2{S.spd[j], fluid ? S.cnv[j] : Packed{0.f, 0.f, 0.f, 0.f}, fluid};
  };
  for_each_entry<kPairBatch2>(list, col, S.nnbr[s], g, gather, [&](int k, const Gather2& nb) {
    const bool use = nb.fluid;  // solid neighbours add nothing
    const Packed q = nb.a, nv = nb.b;
    const vec3 r = p - q.xyz();
    vec3 grad;
    float cf;
    if constexpr (Cached) {
      const Packed gw = S.pair_w[row + k * col];
      grad = gw.xyz(), cf = gw.w;
    } else {
      grad = pair_grad(S.c.W, r), cf = pair_cohesion(S.c.W, coh_c, r);
    }
    vec3 eta, acc;
    force_pair(inv_rho0, two_rho0, st, r, grad, cf, ni, nv.xyz(), nv.w, rho_i, q.w, eta, acc);
    const vec3 zero{0.f, 0.f, 0.f};
    t.eta += use ? eta : zero;
    t.acc += use ? acc : zero;
  });
  return finish_forces(S, s, g.sum(t));
}

// Keckeisen 2004 drag and lift of the triangles around cloth particle s, a third each.
SEAMLESS_HD inline vec3 cloth_aero(const SimViews& S, int s) {
  const int id = S.order[s];
  vec3 f{0.f, 0.f, 0.f};
  for (int e = S.tri_off[id], end = S.tri_off[id + 1]; e < end; ++e) {
    int3 t = S.tri_ids[S.tri_list[e]];
    int a = S.rank[t.x], b = S.rank[t.y], c = S.rank[t.z];
    vec3 vrel = (S.sv[a] + S.sv[b] + S.sv[c]) * (1.f / 3.f) - S.c.wind;
    f += triangle_aero_force(S.sp[a], S.sp[b], S.sp[c], vrel, S.c.drag, S.c.lift, S.c.air_density) * (1.f / 3.f);
  }
  return f * (S.sw[s] * S.c.dt);
}

}  // namespace detail

namespace detail {
// Lane g's share of the vorticity omega_i, the colour-field normal n_i and the XSPH sum of s.
struct VortSum {
  vec3 w, n, dv_visc;
};
SEAMLESS_HD inline VortSum operator+(const VortSum& a, const VortSum& b) {
  return {a.w + b.w, a.n + b.n, a.dv_visc + b.dv_visc};
}

// One pair's terms of VortSum for r = p_i - p_j, the velocities v_i, v_j and h / rho_j (hj), and
// (With) the pair's spiky gradient and cohesion factor for pair_w; F is float or the CPU's SIMD
// lanes (V their vec3).
template <class F, class V> struct VortPair {
  V grad, w, n, dv;
  F cf;
};
template <bool With, class F, class V>
SEAMLESS_HD inline VortPair<F, V> vorticity_pair(const SphKernel& W, float inv_rho0, float coh_c, V r, V vi, V vj,
                                                 F hj) {
  VortPair<F, V> d;
  d.grad = pair_grad(W, r);
  if constexpr (With) d.cf = pair_cohesion(W, coh_c, r);
  d.w = cross(vj - vi, -d.grad) * inv_rho0;
  d.n = d.grad * hj;
  d.dv = (vj - vi) * (W.poly6(length2(r)) * inv_rho0);
  return d;
}

// With Cache, each pair's spiky gradient and cohesion factor are kept in pair_w for
// fluid_forces, which runs next at the same positions.
// Mixed: as pbf_part.
template <bool Cache, bool Mixed> SEAMLESS_HD inline VortSum vorticity_part(const SimViews& S, int s, Lanes g) {
  const float inv_rho0 = 1.f / S.c.rest_density;
  const vec3 p = S.sp[s], vi = S.sv[s];
  constexpr bool mixed = Mixed;
  // Locals: the stores to the caches could otherwise alias the constants in S (reloaded per pair).
  const SphKernel W = S.c.W;
  const float coh_c = -S.c.cohesion * inv_rho0;
  const int* const list = S.nbrs(s);
  const std::int64_t col = S.nbr_col, row = s * S.nbr_row;
  VortSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}};
  // Position (and density), velocity and h / rho, and whether j is fluid.
  const auto gather = [&](int j) {
    return Gather2{S.spd[j], S.svh[j], !mixed || phase::is(S.sphase[j], phase::kFluid)};
  };
  for_each_entry<kPairBatch2>(list, col, S.nnbr[s], g, gather, [&](int k, const Gather2& nb) {
    const Packed q = nb.a, vh = nb.b;
    const VortPair<float, vec3> d = vorticity_pair<Cache>(W, inv_rho0, coh_c, p - q.xyz(), vi, vh.xyz(), vh.w);
    if constexpr (Cache) S.pair_w[row + k * col] = Packed::of(d.grad, d.cf);
    const vec3 zero{0.f, 0.f, 0.f};  // solid neighbours add nothing (selects: for_each_entry)
    t.w += nb.fluid ? d.w : zero;
    t.n += nb.fluid ? d.n : zero;
    t.dv_visc += nb.fluid ? d.dv : zero;
  });
  return t;
}
}  // namespace detail

template <Executor Exec> void Fluid<Exec>::velocity_effects(const Exec& ex, const SimViews& S, bool has_fluid) {
  if (has_fluid) {
    // Vorticity omega_i = sum_j v_ij x grad_j W_ij (PBF eq. 15), Akinci's colour-field normal
    // n_i = h sum_j (1 / rho_j) grad W_ij (Akinci 2013, eq. 4; dissertation eq. 4.21), and the
    // XSPH sum (PBF eq. 17), which needs only this pass's velocities (kept in vtmp for
    // fluid_forces: one neighbour loop fewer that gathers velocities).
    auto vort = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
      const int s = static_cast<int>(i);
      if (!phase::is(S.sphase[s], phase::kFluid)) return;
      constexpr bool kCache = detail::kCachePairs<Exec>;
      const detail::VortSum t = g.sum(S.nsolid[s] != 0 ? detail::vorticity_part<kCache, true>(S, s, g)
                                                       : detail::vorticity_part<kCache, false>(S, s, g));
      if (g.lane != 0) return;
      S.vort[s] = t.w;
      S.vort_len[s] = length(t.w);
      S.cnormal[s] = t.n;
      S.cnv[s] = Packed::of(t.n, S.vort_len[s]);  // what fluid_forces gathers of a neighbour
      S.vtmp[s] = t.dv_visc;
    };
#if !defined(__CUDACC__)
    if (!cpu_tiles(ex, S, detail::vorticity_tile, [=](int s) { vort(s, Lanes{}); }))
#endif
      ex.for_each_grouped(S.n, kPairLanes, vort, detail::kPairOccupancy);
  }
  const bool aero = S.has_cloth_constraints && (S.c.drag > 0.f || S.c.lift > 0.f);
  auto one = [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const std::uint32_t ph = S.sphase[s];
    const bool fluid = has_fluid && phase::is(ph, phase::kFluid);
    vec3 forces{0.f, 0.f, 0.f};
    if (fluid) {
      constexpr bool kCache = detail::kCachePairs<Exec>;
      forces =
          S.nsolid[s] != 0 ? detail::fluid_forces<kCache, true>(S, s, g) : detail::fluid_forces<kCache, false>(S, s, g);
    }
    if (g.lane != 0) return;  // vtmp[s] is read and written by lane 0 only
    vec3 v = S.sv[s];
    if (fluid) v = detail::fluid_velocity(S, s, forces);
    if (aero && phase::is(ph, phase::kCloth)) v += detail::cloth_aero(S, s);
    S.vtmp[s] = v;
  };
#if !defined(__CUDACC__)
  if (!has_fluid || !cpu_tiles(ex, S, detail::forces_tile, [=](int s) { one(s, Lanes{}); }))
#endif
    ex.for_each_grouped(S.n, kPairLanes, one, detail::kPairOccupancy);
}

}  // namespace seamless::kernels
