// Kernel family of the unified particle solver (Macklin, Mueller, Chentanez, Kim 2014), one
// substep of the dissertation's Algorithm 1 split into passes. Every pass reads the SimViews the
// host filled; the host (src/physics/solver.cpp) calls them in this order:
//
//   predict -> sort_by_key -> reorder -> cell_starts -> find_neighbors
//   -> stabilize (section 4.4)
//   -> iterations: prepare_constraints, solve_contacts_fluid (swap sp/tmp), shape_match,
//                  cloth_stretch (all colours, in place), cloth_bend (swap sp/tmp)
//   -> cloth_strain_limit (all passes over the colours, in place)
//   -> update_velocity -> velocity_effects (swap sv/vtmp) -> write_back
#pragma once
#include <cstddef>
#include <cstdint>

#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

// Most lanes per particle of the neighbour loops (Exec::for_each_grouped; the executor takes
// fewer where n particles alone fill the device, and 1 on the CPU). A particle's list holds about
// 30-60 entries at the fluid's rest density, so 16 lanes still have 2-4 entries each, while the
// lanes' sums cost log2(16) = 4 shuffles a word. find_neighbors splits each row's run of
// candidates (about 5 at rest density, reach 2): more than 8 lanes would mostly idle.
constexpr int kPairLanes = 16;
constexpr int kSearchLanes = 8;
// The lists are stored particle by particle (row-major) when at least this many lanes read one
// list: 8 lanes x 4 bytes fill one 32-byte sector (sim_views.hpp).
constexpr int kRowMajorLanes = 8;

// External forces, speed limit, prediction p = x + v dt; cell keys of p; order = identity.
template <class Exec> void predict(const Exec& ex, const SimViews& S);
// Stable sort of (key, value) pairs by the low `bits` bits of key (the executor's radix sort).
template <class Exec> void sort_cells(const Exec& ex, std::uint32_t* keys, int* values, std::int64_t n, int bits);
// Bytes of the executor's temp storage that sort_cells needs (CudaExec::temp; 0 on the CPU).
template <class Exec> std::size_t sort_cells_temp_bytes(const Exec& ex, std::int64_t n, int bits);
// Gathers the sorted arrays after sort_by_key(key, order) and fills rank.
template <class Exec> void reorder(const Exec& ex, const SimViews& S);
// Cell offsets of sorted keys: start[k] = number of keys below k, k in [0, cells] (cells + 1
// entries), so that cell k holds entries [start[k], start[k + 1]) and a run of cells one range.
template <class Exec> void cell_starts(const Exec& ex, const std::uint32_t* keys, std::int64_t n, int* start, std::int64_t cells);
// Keys of arbitrary points (static scene particles) and identity values for a sort.
template <class Exec> void cell_keys(const Exec& ex, const vec3* p, std::int64_t n, GridSpec g, std::uint32_t* keys, int* idx);
template <class Exec> void gather_vec3(const Exec& ex, const vec3* src, const int* idx, std::int64_t n, vec3* dst);
// Neighbour lists (dynamic and static) of every particle within search_radius; counts overflow.
template <class Exec> void find_neighbors(const Exec& ex, const SimViews& S);
// Pre-stabilisation: contacts on the start positions, applied to x and p alike (uses tmp).
template <class Exec> void stabilize(const Exec& ex, const SimViews& S);
// Fluid density and lambda (PBF eqs. 1-11); number of active contacts of every particle.
template <class Exec> void prepare_constraints(const Exec& ex, const SimViews& S);
// Contacts (particles, static particles, SDF) with friction, plus the PBF position update
// (eq. 12/14); writes tmp = sp + correction.
template <class Exec> void solve_contacts_fluid(const Exec& ex, const SimViews& S);
// Shape matching of every rigid body (Mueller 2005): per-body sums, rotation, goal positions.
template <class Exec> void shape_match(const Exec& ex, const SimViews& S);
// Cloth stretch and bending (Mueller 2007); writes tmp.
// Stretch constraints, colour after colour (edges [colour_off[c], colour_off[c + 1]), colour_off
// on the host), in place.
template <class Exec> void cloth_stretch(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours);
// Strain limiting (Provot 1995): `passes` sweeps over the colours, in place.
template <class Exec>
void cloth_strain_limit(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours, int passes);
template <class Exec> void cloth_bend(const Exec& ex, const SimViews& S);
// v = v_pred + (p - p0) / dt (exactly symplectic Euler when nothing acted), restitution, sleeping.
template <class Exec> void update_velocity(const Exec& ex, const SimViews& S);
// XSPH viscosity, vorticity confinement, Akinci cohesion and surface tension, cloth
// aerodynamics; writes vtmp.
template <class Exec> void velocity_effects(const Exec& ex, const SimViews& S, bool has_fluid);
// x, v back to id order; counters[4] = bits of the largest |v|^2 (reset by predict).
template <class Exec> void write_back(const Exec& ex, const SimViews& S);
template <class Exec> void slots_to_ids(const Exec& ex, const SimViews& S, vec3* x_id, std::uint32_t* phase_id);

}  // namespace seamless::kernels

#define SEAMLESS_INSTANTIATE_PHYSICS_SOLVER(E)                                                              \
  namespace seamless::kernels {                                                                             \
  template void predict<E>(const E&, const SimViews&);                                                      \
  template void reorder<E>(const E&, const SimViews&);                                                      \
  template void sort_cells<E>(const E&, std::uint32_t*, int*, std::int64_t, int);                           \
  template void cell_starts<E>(const E&, const std::uint32_t*, std::int64_t, int*, std::int64_t);           \
  template void cell_keys<E>(const E&, const vec3*, std::int64_t, GridSpec, std::uint32_t*, int*);          \
  template void gather_vec3<E>(const E&, const vec3*, const int*, std::int64_t, vec3*);                     \
  template void find_neighbors<E>(const E&, const SimViews&);                                               \
  template void stabilize<E>(const E&, const SimViews&);                                                    \
  template void prepare_constraints<E>(const E&, const SimViews&);                                          \
  template void solve_contacts_fluid<E>(const E&, const SimViews&);                                         \
  template void shape_match<E>(const E&, const SimViews&);                                                  \
  template void cloth_stretch<E>(const E&, const SimViews&, const std::int64_t*, int);                      \
  template void cloth_strain_limit<E>(const E&, const SimViews&, const std::int64_t*, int, int);             \
  template void cloth_bend<E>(const E&, const SimViews&);                                                  \
  template void update_velocity<E>(const E&, const SimViews&);                                              \
  template void velocity_effects<E>(const E&, const SimViews&, bool);                                       \
  template void write_back<E>(const E&, const SimViews&);                                                   \
  template void slots_to_ids<E>(const E&, const SimViews&, vec3*, std::uint32_t*);                          \
  template std::size_t sort_cells_temp_bytes<E>(const E&, std::int64_t, int);                              \
  }
