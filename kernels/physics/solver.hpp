// The unified particle solver's kernels (Macklin, Mueller, Chentanez, Kim 2014): one substep of
// the dissertation's Algorithm 1 split into passes, grouped in kernel families by concern. Every
// pass reads the SimViews the host filled; the host (src/physics/particle_solver.cpp) calls them
// in this order:
//
//   NeighbourGrid (grid.hpp): predict -> sort_cells -> reorder -> cell_starts -> find_neighbors
//   -> Contacts (contacts.hpp): stabilize (section 4.4)
//   -> iterations: Fluid::prepare_constraints, Fluid::solve_contacts_fluid (swap sp/tmp),
//                  Solids::shape_match, Solids::cloth_stretch (all colours, in place),
//                  Solids::cloth_bend (swap sp/tmp)
//   -> Solids::cloth_strain_limit (all passes over the colours, in place)
//   -> Integration::update_velocity -> Fluid::velocity_effects (swap sv/vtmp)
//   -> Integration::write_back
//
// Shared pair helpers are in pair_math.hpp, the contact helpers in contacts.inl, the CPU's SIMD
// tiles in cpu_tiles.hpp/.cpp.
#pragma once
#include "kernels/physics/contacts.hpp"
#include "kernels/physics/fluid.hpp"
#include "kernels/physics/grid.hpp"
#include "kernels/physics/integration.hpp"
#include "kernels/physics/sim_views.hpp"
#include "kernels/physics/solids.hpp"

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

}  // namespace seamless::kernels
