// What the solver's kernels see: one POD of constants and device pointers, filled by the host
// (src/physics/particle_solver.cpp) for each substep. Arrays marked "id" are indexed by particle id
// (the order the user spawned them in); arrays marked "sorted" are in neighbour-grid cell order,
// which the solver re-establishes every substep for memory coherence (Green 2010); arrays marked
// "slot" hold the state between substeps in the last substep's sorted order (slot_id gives the
// particle in each slot), so that the next sort starts from an almost sorted order: the gather of
// the state into the new order reads nearly consecutive slots, and writing it back needs no
// scatter by id (both lost coherence as a fluid mixes; docs/PERFORMANCE.md).
#pragma once
#include <cstdint>

#include "core/math.hpp"
#include "kernels/physics/particle_math.hpp"
#include "kernels/physics/scene_sdf.hpp"

namespace seamless::kernels {

struct Quad {
  int a, b, c, d;  // bending: a, b = shared edge; c, d = the opposite vertices (Mueller 2007, A)
};

// Per-chunk partial sums of shape matching: sum of (p - ref) and sum of (p - ref) q^T.
struct RigidSum {
  vec3 p;
  mat3 A;
};
SEAMLESS_HD inline RigidSum operator+(const RigidSum& a, const RigidSum& b) { return {a.p + b.p, a.A + b.A}; }

// Per-chunk sums of a body's particles touching the scene (kernels::body_static_friction):
// tangential displacement over the step now and as predicted, normal correction in the step, count.
struct SlipSum {
  vec3 t, free;
  float push, count;
};
SEAMLESS_HD inline SlipSum operator+(const SlipSum& a, const SlipSum& b) {
  return {a.t + b.t, a.free + b.free, a.push + b.push, a.count + b.count};
}

struct SimConstants {
  float dt = 0.01f, inv_dt = 100.f;
  vec3 gravity{0.f, -9.81f, 0.f};
  float radius = 0.02f, diameter = 0.04f;  // contact distance = diameter (one radius per solver)
  float search_radius = 0.08f;             // neighbour radius = grid cell size
  float max_speed = 4.f;
  float omega = 1.f;  // SOR factor of averaged constraints (Macklin 2014, eq. 11)
  float static_friction = 0.5f, kinetic_friction = 0.3f, restitution = 0.f;
  float fluid_friction = 0.f;  // fluid against the scene and solids (0: fluids slip)
  // Position Based Fluids (Macklin & Mueller 2013), in number-density units.
  float h = 0.08f;                           // smoothing radius
  SphKernel W = SphKernel::make(0.08f);      // kernels of radius h (host: SphKernel::make(h))
  float rest_density = 1.f;                  // rho_0: kernel sum of the rest lattice
  float relaxation = 1.f;                    // epsilon of eq. 11 (CFM)
  float scorr_k = 0.f, scorr_inv_wdq = 0.f;  // tensile instability term, eq. 13
  int unilateral = 1;                        // C_i <= 0 only (Macklin 2014, section 7.1)
  float solid_density_scale = 1.f;           // weight of solid neighbours in fluid density (ibid.)
  float viscosity = 0.01f, vorticity = 0.f, cohesion = 0.f, surface_tension = 0.f;
  // cloth aerodynamics (Keckeisen 2004)
  float drag = 0.f, lift = 0.f, air_density = 1.2f;
  vec3 wind{0.f, 0.f, 0.f};
  float sleep_threshold = 0.f;
  float cloth_self_exclusion = 0.06f;
  float strain_omega = 1.5f;           // over-relaxation of cloth strain limiting (Provot 1995)
  float strain_contact_weight = 0.3f;  // inverse-mass factor there of particles touching the scene  // same-cloth pairs
                                       // closer than this at rest never collide
  int max_neighbors = 64, max_static_neighbors = 64;
  int rotation_iterations = 8;
};

struct SimViews {
  SimConstants c;
  std::int64_t n = 0;  // active dynamic particles

  // slot: the state between substeps
  vec3* x = nullptr;
  vec3* v = nullptr;
  float* w = nullptr;  // inverse mass; 0 = pinned
  std::uint32_t* phase = nullptr;
  int* slot_id = nullptr;  // slot -> id
  vec3* pred = nullptr;    // predicted positions before sorting
  // id: per-particle constants
  const vec3* rest = nullptr;  // rigid: offset from the body's rest centre; cloth: rest position
  const vec4* rsdf = nullptr;  // rigid: body-frame SDF gradient (xyz) and value (w, < 0 inside)

  // sort
  std::uint32_t* key = nullptr;
  int* order = nullptr;  // sorted index -> slot (the sort's values), then -> id (reorder)
  int* rank = nullptr;   // id -> sorted index

  // sorted
  vec3 *sx = nullptr, *sp = nullptr, *sp0 = nullptr, *sv = nullptr, *tmp = nullptr, *vtmp = nullptr;
  float* sw = nullptr;
  std::uint32_t* sphase = nullptr;
  float* lambda = nullptr;
  float* density = nullptr;
  float* h_rho = nullptr;     // h / density
  float* vort_len = nullptr;  // |vort|
  int* ncontacts = nullptr;
  vec3 *vort = nullptr, *cnormal = nullptr;
  vec4* sdf_at = nullptr;  // scene SDF gradient (xyz) and distance (w) at the last counted positions
  // Packed copies for the neighbour loops (one 16-byte load per neighbour, kernels::Packed):
  // spk = (sp, phase bits), written by reorder (for find_neighbors) and at the start of
  // prepare_constraints; spl = (sp, lambda) by prepare_constraints for solve_contacts_fluid;
  // spd = (sp, density) and svh = (sv, h_rho) by update_velocity and cnv = (cnormal, vort_len)
  // by the vorticity pass, for velocity_effects.
  Packed *spk = nullptr, *spl = nullptr, *spd = nullptr, *svh = nullptr, *cnv = nullptr;
  // CPU only (kernels::kCachePairs): per list entry (the lists' layout), the spiky gradient
  // (xyz) and poly6 value (w) of the pair at prepare_constraints' positions, which
  // solve_contacts_fluid reuses (the same positions) instead of recomputing them.
  // velocity_effects reuses it (free after the last solve) for the spiky gradient (xyz) and the
  // Akinci cohesion factor (w) at the final positions: the vorticity pass computes them, the
  // forces pass reads them.
  Packed* pair_w = nullptr;

  // Neighbour grid and lists. Entry k of particle s's list is list[s * row + k * col]: the layout
  // is the executor's choice (the host sets the strides). A CPU thread walks one particle's list,
  // which should be contiguous (row-major: row = cap, col = 1); a GPU warp reads entry k of 32
  // particles at once, which should be contiguous (column-major: row = 1, col = n). Each list has
  // cap + 1 slots: find_neighbors writes rejected candidates to the spare slot past the last kept.
  GridSpec grid{};
  int* cell_start = nullptr;  // cells + 1 offsets (kernels::cell_starts)
  int *nbr = nullptr, *nnbr = nullptr;
  int *snbr = nullptr, *nsnbr = nullptr;
  std::int64_t nbr_row = 0, nbr_col = 0, snbr_row = 0, snbr_col = 0;
  int* nsolid = nullptr;  // list entries of s that are not fluid-fluid pairs (contacts, solid coupling)
  SEAMLESS_HD const int* nbrs(int s) const { return nbr + s * nbr_row; }
  SEAMLESS_HD const int* snbrs(int s) const { return snbr + s * snbr_row; }
  // [0] lists over the cap, [1] static lists over the cap, [2] max len, [3] max static len,
  // [4] bits of the largest |v|^2 at the last write_back (float_bits, core/math.hpp)
  int* counters = nullptr;

  // static scene particles, sorted by their own grid at upload
  std::int64_t ns = 0;
  const vec3* stat = nullptr;
  GridSpec sgrid{};
  const int* scell_start = nullptr;
  SceneSdf sdf{};

  // rigid bodies: particles of body b are ids [body_start[b], body_start[b] + body_count[b])
  int nbodies = 0;
  const int *body_start = nullptr, *body_count = nullptr;
  const int *body_chunk_start = nullptr, *body_chunk_count = nullptr;
  const float* body_stiffness = nullptr;
  int* body_contacts = nullptr;  // particles of the body touching the scene (this iteration)
  vec3* body_c = nullptr;        // centre of mass (also the reference point of the next sums)
  vec3* body_shift = nullptr;    // scratch: new centre minus body_c
  vec4* body_q = nullptr;
  mat3* body_R = nullptr;
  int nchunks = 0;
  const int *chunk_start = nullptr, *chunk_count = nullptr, *chunk_body = nullptr;
  RigidSum* chunk_sum = nullptr;
  SlipSum* chunk_slip = nullptr;
  vec3* scene_n = nullptr;  // sum of the scene contact normals at the last count (count_contacts)

  // cloth stretch constraints (ids), grouped by colour: no particle has two edges of one colour
  // (the host colours them), so one colour's edges are projected in place in one pass. Rest
  // length, stiffness and the strain limit (0 = none; Provot 1995) per edge.
  const int *edge_a = nullptr, *edge_b = nullptr;
  const float *edge_len = nullptr, *edge_k = nullptr, *edge_limit = nullptr;
  // cloth, CSR by id: bending constraints and triangles incident to each particle; a bend_list
  // entry is the slot 4 b + vertex in bend_delta of the particle's correction by constraint b
  const int *bend_off = nullptr, *bend_list = nullptr;
  const Quad* bend_ids = nullptr;
  const float *bend_rest = nullptr, *bend_k = nullptr;
  std::int64_t nbends = 0;
  vec3* bend_delta = nullptr;  // scratch: 4 corrections per bending constraint
  const int *tri_off = nullptr, *tri_list = nullptr;
  const int3* tri_ids = nullptr;
  int has_cloth_constraints = 0;
};

}  // namespace seamless::kernels
