// Kernel bodies of physics/contacts.hpp, and the contact helpers (particle, static-particle and
// scene SDF contacts with friction) that the fluid family's passes and the CPU tiles share.
#pragma once
#include "kernels/physics/contacts.hpp"
#include "kernels/physics/pair_math.hpp"

namespace seamless::kernels {

namespace detail {

struct PairGeom {
  bool hit;
  vec3 n;  // unit, pushes particle s away from j
  float depth;
};

// Contact between dynamic particles s and j at positions P (Macklin 2014, eq. 4.3 of the
// dissertation). Between two rigid bodies whose particles are both below the surface layer, the
// bodies have interpenetrated deeply; the stored SDF of the shallower particle then gives the
// direction and depth (Macklin 2014, section 5), so the bodies separate the short way.
SEAMLESS_HD inline PairGeom pair_geometry(const SimViews& S, int s, int j, const vec3* P) {
  const float D = S.c.diameter;
  vec3 d = P[s] - P[j];
  float l2 = length2(d);
  if (l2 >= D * D) return {false, {0.f, 0.f, 0.f}, 0.f};
  float l = sqrtf(l2);
  PairGeom g{true, l > 1e-9f ? d / l : vec3{0.f, 1.f, 0.f}, D - l};
  std::uint32_t pi = S.sphase[s], pj = S.sphase[j];
  if (phase::is(pi, phase::kRigid) && phase::is(pj, phase::kRigid) && S.rsdf) {
    const int idi = S.order[s], idj = S.order[j];
    vec4 gi = S.rsdf[idi], gj = S.rsdf[idj];
    float ai = fabsf(gi.w), aj = fabsf(gj.w);
    if (fminf(ai, aj) > D) {
      // Both particles of the pair must pick the same SDF (ties broken by id), so that their
      // corrections stay opposite.
      if (ai < aj || (ai == aj && idi < idj)) g = {true, -(S.body_R[phase::group(pi)] * xyz(gi)), ai};
      else g = {true, S.body_R[phase::group(pj)] * xyz(gj), aj};
    }
  }
  return g;
}

// Entries of s's particle list that can be contacts: none for a fluid particle whose list holds
// only fluid (fluids meet through the density constraint), so its loops are skipped.
SEAMLESS_HD inline int contact_list_len(const SimViews& S, int s) {
  return phase::is(S.sphase[s], phase::kFluid) && S.nsolid[s] == 0 ? 0 : S.nnbr[s];
}

// Particle and scene-particle contacts of one lane's share of s's lists, and the sum of the scene
// contact normals there (summed over the lanes with Lanes::sum).
struct ContactCount {
  int count, scene;
  vec3 sn;
};
SEAMLESS_HD inline ContactCount operator+(const ContactCount& a, const ContactCount& b) {
  return {a.count + b.count, a.scene + b.scene, a.sn + b.sn};
}

// Number of active contacts of particle s at positions P (at least 1: it divides), in lane 0 (the
// lanes of g split s's lists). A rigid particle touching the scene also counts itself in its
// body's body_contacts.
SEAMLESS_HD inline int count_contacts(const SimViews& S, int s, const vec3* P, Lanes g) {
  const float D2 = S.c.diameter * S.c.diameter;
  const int m = contact_list_len(S, s), ms = S.nsnbr[s];
  const vec3 p = P[s];
  ContactCount c{0, 0, {0.f, 0.f, 0.f}};
  for (int k = g.lane; k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    if (both_fluid(S.sphase[s], S.sphase[j])) continue;
    if (length2(p - P[j]) < D2) ++c.count;
  }
  for (int k = g.lane; k < ms; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    float l2 = length2(r);
    if (l2 < D2) {
      ++c.scene;
      if (l2 > 1e-18f) c.sn += r / sqrtf(l2);
    }
  }
  if (m > 0 || ms > 0) c = g.sum(c);  // m, ms are s's: the same in every lane
  if (g.lane != 0) return 1;
  int count = c.count, scene = c.scene;
  vec3 sn = c.sn;  // sum of the scene contact normals
  if (S.sdf.active()) {
    // Kept for add_sdf_contact, which runs next at the same positions (the SDF costs more than the
    // rest of a fluid particle's contact work).
    SdfSample3 q = scene_sdf(S.sdf, p);
    S.sdf_at[s] = vec4{q.grad.x, q.grad.y, q.grad.z, q.d};
    if (q.d < S.c.radius) ++scene, sn += q.grad;
  }
  S.scene_n[s] = sn;
  if (scene > 0 && phase::is(S.sphase[s], phase::kRigid)) atomic_add(&S.body_contacts[phase::group(S.sphase[s])], 1);
  count += scene;
  return count > 0 ? count : 1;
}

// The two passes that project contacts: pre-stabilisation on the start positions (Macklin 2014,
// section 4.4: no friction, and no shape matching after it) and the solver iterations.
enum class ContactPass { kStabilize, kSolve };

// Weight of s's scene contacts: omega / n_s, and in the solver iterations for a rigid particle
// times (body particles / body particles touching the scene): shape matching spreads a particle's
// correction over the whole body, and without this a flat face resting on the scene would resolve
// only a fraction of its contact (and of its static friction) per iteration, so that resting
// bodies creep. Not in pre-stabilisation: no shape matching follows it there, so the factor (up to
// N for a body of N particles resting on one) would leave the body deformed by that many times its
// penetration, on x and p alike, and the next iteration's shape matching would turn the
// deformation into velocity: a cube resting on a real scan's bumps was kicked at up to 9.6 m/s.
SEAMLESS_HD inline float scene_contact_weight(const SimViews& S, int s, ContactPass pass) {
  const std::uint32_t ph = S.sphase[s];
  float self = S.c.omega / static_cast<float>(S.ncontacts[s]);
  if (pass == ContactPass::kSolve && phase::is(ph, phase::kRigid)) {
    int b = static_cast<int>(phase::group(ph));
    self *= static_cast<float>(S.body_count[b]) / static_cast<float>(max(S.body_contacts[b], 1));
  }
  return self;
}

// One lane's share of the contact corrections of s at positions P (start positions X for
// friction) with particles and scene particles; the contact sum is the lanes' sum plus add_sdf_contact. Runs
// after count_contacts at the same positions. Each pair's correction is scaled by
// omega / max(n_s, n_j): averaging as in Macklin 2014 (eq. 11) that keeps every pair's two
// corrections equal and opposite, so momentum is conserved.
SEAMLESS_HD inline vec3 contact_part(const SimViews& S, int s, const vec3* P, const vec3* X, ContactPass pass,
                                     Lanes g) {
  const bool friction = pass == ContactPass::kSolve;
  const float D = S.c.diameter, wi = S.sw[s];
  const bool fl = phase::is(S.sphase[s], phase::kFluid);
  const vec3 p = P[s], dx = p - X[s];
  const float ni = static_cast<float>(S.ncontacts[s]);
  const float mus = friction ? S.c.static_friction : 0.f, muk = friction ? S.c.kinetic_friction : 0.f;
  const float fmu = friction ? S.c.fluid_friction : 0.f;
  vec3 acc{0.f, 0.f, 0.f};
  for (int k = g.lane, m = contact_list_len(S, s); k < m; k += g.size) {
    int j = S.nbrs(s)[k * S.nbr_col];
    std::uint32_t phj = S.sphase[j];
    if (fl && phase::is(phj, phase::kFluid)) continue;
    PairGeom pg = pair_geometry(S, s, j, P);
    if (!pg.hit) continue;
    // Fluid against a solid: solver.fluid_friction for both coefficients (0: fluids slip).
    bool any_fluid = fl || phase::is(phj, phase::kFluid);
    vec3 rel = dx - (P[j] - X[j]);
    float scale = S.c.omega / fmaxf(ni, static_cast<float>(S.ncontacts[j]));
    acc += contact_delta(pg.n, pg.depth, rel, wi, S.sw[j], any_fluid ? fmu : mus, any_fluid ? fmu : muk) * scale;
  }
  const int ms = S.nsnbr[s];
  if (ms == 0) return acc;
  const float self = scene_contact_weight(S, s, pass);
  const float smu_s = fl ? fmu : mus, smu_k = fl ? fmu : muk;
  for (int k = g.lane; k < ms; k += g.size) {
    vec3 r = p - S.stat[S.snbrs(s)[k * S.snbr_col]];
    float l2 = length2(r);
    if (l2 >= D * D) continue;
    float l = sqrtf(l2);
    vec3 n = l > 1e-9f ? r / l : vec3{0.f, 1.f, 0.f};
    acc += contact_delta(n, D - l, dx, wi, 0.f, smu_s, smu_k) * self;
  }
  return acc;
}

// Adds the scene SDF's contact correction of s (sampled by count_contacts at the same positions)
// to acc, where the SDF touches s.
SEAMLESS_HD inline void add_sdf_contact(const SimViews& S, int s, const vec3* P, const vec3* X, ContactPass pass,
                                        vec3& acc) {
  const bool friction = pass == ContactPass::kSolve;
  if (!S.sdf.active()) return;
  const vec4 q = S.sdf_at[s];  // scene_sdf(S.sdf, p), stored by count_contacts
  if (!(q.w < S.c.radius)) return;
  const bool fl = phase::is(S.sphase[s], phase::kFluid);
  const float mu_s = !friction ? 0.f : fl ? S.c.fluid_friction : S.c.static_friction;
  const float mu_k = !friction ? 0.f : fl ? S.c.fluid_friction : S.c.kinetic_friction;
  acc +=
      contact_delta(xyz(q), S.c.radius - q.w, P[s] - X[s], S.sw[s], 0.f, mu_s, mu_k) * scene_contact_weight(S, s, pass);
}

// Whether s has list entries that contact_part visits (otherwise its lanes need no sum).
SEAMLESS_HD inline bool has_contact_lists(const SimViews& S, int s) {
  return contact_list_len(S, s) > 0 || S.nsnbr[s] > 0;
}

}  // namespace detail

// Macklin 2014, section 4.4: contacts that already exist at the start positions are resolved on
// x and p together, so that they are removed without adding velocity.
template <Executor Exec> void Contacts<Exec>::stabilize(const Exec& ex, const SimViews& S) {
  ex.for_each(S.nbodies, [=] SEAMLESS_HD(std::int64_t b) { S.body_contacts[b] = 0; });
  ex.for_each_grouped(S.n, kPairLanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    const int nc = detail::count_contacts(S, s, S.sx, g);
    if (g.lane == 0) S.ncontacts[s] = nc;
  });
  ex.for_each_grouped(S.n, kPairLanes, [=] SEAMLESS_HD(std::int64_t i, Lanes g) {
    const int s = static_cast<int>(i);
    if (!(S.sw[s] > 0.f)) {
      if (g.lane == 0) S.tmp[s] = {0.f, 0.f, 0.f};
      return;
    }
    vec3 acc = detail::contact_part(S, s, S.sx, S.sx, detail::ContactPass::kStabilize, g);
    if (detail::has_contact_lists(S, s)) acc = g.sum(acc);
    if (g.lane != 0) return;
    detail::add_sdf_contact(S, s, S.sx, S.sx, detail::ContactPass::kStabilize, acc);
    S.tmp[s] = acc;
  });
  ex.for_each(S.n, [=] SEAMLESS_HD(std::int64_t s) {
    vec3 d = S.tmp[s];
    S.sx[s] += d;
    S.sp[s] += d;
    S.sp0[s] += d;
  });
}

}  // namespace seamless::kernels
