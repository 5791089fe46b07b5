// Kernel bodies of physics/integration.hpp: velocities from positions, and the sorted state back
// to the slots.
#pragma once
#include "kernels/physics/integration.hpp"
#include "kernels/physics/pair_math.hpp"

namespace seamless::kernels {

template <Executor Exec> void Integration<Exec>::update_velocity(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    // v_pred + (p - p0)/dt equals (p - x)/dt, but is exactly v_pred when no constraint acted.
    vec3 v = S.sv[s] + (S.sp[s] - S.sp0[s]) * S.c.inv_dt;
    if (S.c.sleep_threshold > 0.f && length2(v) < S.c.sleep_threshold * S.c.sleep_threshold) {
      v = {0.f, 0.f, 0.f};  // Macklin 2014, section 4.5: slow particles keep their position
      S.sp[s] = S.sx[s];
    }
    if (S.c.restitution > 0.f && S.sdf.active()) {
      // Restitution against the scene SDF: reflect the approach speed of the step's start.
      SdfSample3 q = scene_sdf(S.sdf, S.sp[s]);
      float vn0 = dot(S.sv[s], q.grad), vn = dot(v, q.grad);
      if (q.d < S.c.radius * 1.01f && vn0 < 0.f) v += q.grad * (-S.c.restitution * vn0 - vn);
    }
    S.sv[s] = v;
    // What velocity_effects' loops gather of a neighbour (the phase, needed only among solids,
    // is read from sphase there): (sp, density), the position final here, and (v, h / rho).
    S.spd[s] = Packed::of(S.sp[s], S.density[s]);
    S.svh[s] = Packed::of(v, S.h_rho[s]);
  });
}

// The sorted state becomes the slot state (slot s = sorted index s: coalesced, no scatter by id).
template <Executor Exec> void Integration<Exec>::write_back(const Exec& ex, const SimViews& S) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    S.x[s] = S.sp[s];
    S.v[s] = S.sv[s];
    S.w[s] = S.sw[s];
    S.phase[s] = S.sphase[s];
    S.slot_id[s] = S.order[s];
    // Largest |v|^2 for stats() without a reduction: the bits of non-negative floats order like
    // ints. Read first: the shared maximum rarely changes, so most particles only load it.
    const int v2 = float_bits(length2(S.sv[s]));
    if (v2 > atomic_load(&S.counters[4])) atomic_max(&S.counters[4], v2);
  });
}

// The slot state's positions and phases in id order (for what reads particles by id: the
// renderer's cloth triangles, downloads).
template <Executor Exec>
void Integration<Exec>::slots_to_ids(const Exec& ex, const SimViews& S, vec3* x_id, std::uint32_t* phase_id) {
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    const int id = S.slot_id[s];
    x_id[id] = S.x[s];
    phase_id[id] = S.phase[s];
  });
}

}  // namespace seamless::kernels
