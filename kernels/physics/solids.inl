// Kernel bodies of physics/solids.hpp: rigid shape matching and the cloth constraints.
#pragma once
#include "kernels/physics/pair_math.hpp"
#include "kernels/physics/solids.hpp"

namespace seamless::kernels {

// Static friction of a rigid body as a whole (Macklin 2014, section 6.1, applied to the body):
// shape matching moves the particles touching the scene after their contacts removed their
// tangential displacement (it turns the body a little under the friction torque at its base), and
// by the next iteration their contacts are resolved, so the static-friction bound mu_s * depth of
// the particle contacts is near zero and nothing removes that slip again: a body held by static
// friction crept down an incline. Here, after shape matching, the mean tangential displacement t
// over the step of the body's touching particles (tangential to each particle's scene normal) is
// removed by moving the whole body back by t, where static friction holds: where the tangential
// displacement the prediction asked for (sp0 - x, before any correction) is below mu_s times the
// mean normal correction in the step (eq. 24's condition, for the body's contact patch). The
// contact points then stay put on average, without a torque (the body may still turn about them).
// Otherwise the particles' kinetic friction acts alone.
template <Executor Exec> void Solids<Exec>::body_static_friction(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nchunks, [=] SEAMLESS_HD(std::int64_t c) {
    SlipSum sum{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, 0.f, 0.f};
    for (int id = S.chunk_start[c], e = S.chunk_start[c] + S.chunk_count[c]; id < e; ++id) {
      const int s = S.rank[id];
      const vec3 sn = S.scene_n[s];
      const float l = length(sn);
      if (!(l > 0.f)) continue;
      const vec3 n = sn / l, dx = S.sp[s] - S.sx[s], free = S.sp0[s] - S.sx[s];
      sum.t += dx - n * dot(dx, n);
      sum.free += free - n * dot(free, n);
      sum.push += fmaxf(dot(n, S.sp[s] - S.sp0[s]), 0.f);
      sum.count += 1.f;
    }
    S.chunk_slip[c] = sum;
  });
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) {
    SlipSum t{{0.f, 0.f, 0.f}, {0.f, 0.f, 0.f}, 0.f, 0.f};
    for (int c = S.body_chunk_start[b], e = c + S.body_chunk_count[b]; c < e; ++c) t = t + S.chunk_slip[c];
    vec3 back{0.f, 0.f, 0.f};
    if (t.count > 0.f && length(t.free) < S.c.static_friction * t.push) back = -t.t / t.count;
    S.body_shift[b] = back;
    S.body_c[b] = S.body_c[b] + back;
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    std::uint32_t ph = S.sphase[s];
    if (phase::is(ph, phase::kRigid) && S.sw[s] > 0.f) S.sp[s] += S.body_shift[phase::group(ph)];
  });
}

template <Executor Exec> void Solids<Exec>::shape_match(const Exec& ex, const SimViews& S) {
  if (S.nbodies == 0) return;
  // Partial sums over fixed-size chunks of each body's particles, then per-body totals: a
  // deterministic segmented reduction (no float atomics). Offsets are taken from the previous
  // centre so that sum (p - ref) q^T does not cancel catastrophically far from the origin.
  ex.for_each(S.nchunks, [=] SEAMLESS_HD(std::int64_t c) {
    vec3 ref = S.body_c[S.chunk_body[c]];
    RigidSum sum{{0.f, 0.f, 0.f}, mat3::zero()};
    for (int id = S.chunk_start[c], e = S.chunk_start[c] + S.chunk_count[c]; id < e; ++id) {
      vec3 d = S.sp[S.rank[id]] - ref;
      sum.p += d;
      sum.A = sum.A + outer(d, S.rest[id]);
    }
    S.chunk_sum[c] = sum;
  });
  // Mueller 2005: c = mean position (eq. 4.4), A_pq = sum (p - c) q^T = sum (p - ref) q^T because
  // the rest offsets q sum to zero; R = rotational part of A_pq (eq. 4.5), found on the device.
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) {
    RigidSum t{{0.f, 0.f, 0.f}, mat3::zero()};
    for (int c = S.body_chunk_start[b], e = c + S.body_chunk_count[b]; c < e; ++c) t = t + S.chunk_sum[c];
    vec3 shift = t.p / static_cast<float>(S.body_count[b]);
    vec4 q = extract_rotation(t.A, S.body_q[b], S.c.rotation_iterations);
    S.body_q[b] = q;
    S.body_R[b] = quat_to_mat(q);
    S.body_shift[b] = shift;
  });
  // Goal positions g_i = R q_i + c (eq. 4.6), approached with the body's stiffness. The
  // correction is formed relative to the reference point, so that its rounding error is relative
  // to the body's size rather than to the distance from the origin (velocities are corrections
  // divided by dt: this keeps momentum at float precision).
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    std::uint32_t ph = S.sphase[s];
    if (!phase::is(ph, phase::kRigid) || !(S.sw[s] > 0.f)) return;
    int b = static_cast<int>(phase::group(ph));
    vec3 local = S.sp[s] - S.body_c[b];
    vec3 goal = S.body_R[b] * S.rest[S.order[s]] + S.body_shift[b];
    S.sp[s] += (goal - local) * S.body_stiffness[b];
  });
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_c[b] = S.body_c[b] + S.body_shift[b]; });
  if (S.c.static_friction > 0.f) body_static_friction(ex, S);
}

// Stretch constraints (Mueller 2007, eq. 4.7/4.8), colour after colour: edges
// [colour_off[c], colour_off[c + 1]). The host colours the edges so that no particle has two edges
// of one colour: each colour is then projected fully and in place (Gauss-Seidel over colours, the
// usual graph colouring of parallel PBD) instead of averaged (Jacobi), which with 8 edges per
// particle and 2 iterations left hanging cloth stretched by 20 %. One task per edge writes both
// of its particles, which no other task of the colour touches. The colours are the phases of one
// for_each_phases sweep (one launch for a small cloth on CUDA, the same order as a launch each).
template <Executor Exec>
void Solids<Exec>::cloth_stretch(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours) {
  // What the sweep reads, staged for it (in fast memory where the executor can, most valuable
  // first: the positions it writes, then the per-particle and per-edge constants).
  const std::int64_t ne = colour_off[colours];
  ex.for_each_phases_staged(
      colours, colour_off, colour_off + 1,
      [=] SEAMLESS_HD(int, std::int64_t e, vec3* sp, const float* sw, const int* rank, const int* ea, const int* eb,
                      const float* len, const float* stiff) {
        const int a = rank[ea[e]], b = rank[eb[e]];
        const vec3 pa = sp[a], pb = sp[b];
        const float wa = sw[a], wb = sw[b], L = len[e], k = stiff[e];
        sp[a] = pa + distance_delta(pa, pb, wa, wb, L, k);
        sp[b] = pb + distance_delta(pb, pa, wb, wa, L, k);
      },
      Staged<vec3>{S.sp, S.n}, Staged<const float>{S.sw, S.n}, Staged<const int>{S.rank, S.n},
      Staged<const int>{S.edge_a, ne}, Staged<const int>{S.edge_b, ne}, Staged<const float>{S.edge_len, ne},
      Staged<const float>{S.edge_k, ne});
}

// Strain limiting (Provot 1995, section 5): after the solver iterations, `passes` Gauss-Seidel
// sweeps over the edge colours (as in cloth_stretch, all in one for_each_phases sweep); every edge
// stretched or compressed by more than its limit (a fraction of the rest length) is brought back
// to the limit (over-relaxed by cloth_strain_omega), in place; edges within the limit are left
// alone. This pass cannot see the contacts, so a particle that touched the scene in the last
// iteration (scene_n != 0) counts as heavier (inverse mass times strain_contact_weight): the
// scene holds it, and the free part of the cloth takes more of the correction instead of the
// limiter pulling the particle into the scene (mass scaling in the spirit of Macklin 2014's
// stacking heuristic).
template <Executor Exec>
void Solids<Exec>::cloth_strain_limit(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours,
                                      int passes) {
  std::vector<std::int64_t> begin, end;
  for (int pass = 0; pass < passes; ++pass)
    for (int c = 0; c < colours; ++c) begin.push_back(colour_off[c]), end.push_back(colour_off[c + 1]);
  // Staged as in cloth_stretch (32 phases for 4 passes over 8 colours: the most to gain).
  const std::int64_t ne = colour_off[colours];
  const float cw = S.c.strain_contact_weight, om = S.c.strain_omega;
  ex.for_each_phases_staged(
      static_cast<int>(begin.size()), begin.data(), end.data(),
      [=] SEAMLESS_HD(int, std::int64_t e, vec3* sp, const float* sw, const int* rank, const vec3* scene_n,
                      const int* ea, const int* eb, const float* len, const float* limit) {
        const float lim = limit[e];
        if (!(lim > 0.f)) return;
        const int a = rank[ea[e]], b = rank[eb[e]];
        const vec3 pa = sp[a], pb = sp[b];
        const float L = len[e];
        const float wa = sw[a] * (length2(scene_n[a]) > 0.f ? cw : 1.f);
        const float wb = sw[b] * (length2(scene_n[b]) > 0.f ? cw : 1.f);
        sp[a] = pa + strain_limit_delta(pa, pb, wa, wb, L, lim, om);
        sp[b] = pb + strain_limit_delta(pb, pa, wb, wa, L, lim, om);
      },
      Staged<vec3>{S.sp, S.n}, Staged<const float>{S.sw, S.n}, Staged<const int>{S.rank, S.n},
      Staged<const vec3>{S.scene_n, S.n}, Staged<const int>{S.edge_a, ne}, Staged<const int>{S.edge_b, ne},
      Staged<const float>{S.edge_len, ne}, Staged<const float>{S.edge_limit, ne});
}

// Bending constraints (Jacobi, averaged through their stiffness on the host): each constraint's
// four corrections once (bend_delta[4 b + vertex]), then every particle gathers its own, in the
// order of its incidence list (no float atomics), which names the slots directly (one dependent
// load less than looking the vertex up in the constraint's Quad).
template <Executor Exec> void Solids<Exec>::cloth_bend(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbends, [=] SEAMLESS_HD(std::int64_t b) {
    Quad q = S.bend_ids[b];
    int ids[4] = {q.a, q.b, q.c, q.d};
    vec3 pos[4];
    float w[4];
    for (int k = 0; k < 4; ++k) {
      int sk = S.rank[ids[k]];
      pos[k] = S.sp[sk];
      w[k] = S.sw[sk];
    }
    bending_deltas(pos, w, S.bend_rest[b], S.bend_k[b], S.bend_delta + 4 * b);
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t i) {
    const int s = static_cast<int>(i);
    const vec3 p = S.sp[s];
    if (!phase::is(S.sphase[s], phase::kCloth) || !(S.sw[s] > 0.f)) {
      S.tmp[s] = p;
      return;
    }
    const int id = S.order[s];
    vec3 acc{0.f, 0.f, 0.f};
    // bend_list holds the slots 4 b + vertex of id's corrections (the host resolved the vertex).
    for (int e = S.bend_off[id], end = S.bend_off[id + 1]; e < end; ++e) acc += S.bend_delta[S.bend_list[e]];
    S.tmp[s] = p + acc;
  });
}

}  // namespace seamless::kernels
