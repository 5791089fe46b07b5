// Kernel family of the contacts on their own (solver.hpp lists the passes in order). The contact
// helpers themselves (contacts.inl, namespace detail) also serve the fluid family's combined
// contact and density pass and the CPU tiles.
#pragma once
#include "core/exec.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

template <Executor Exec> struct Contacts {
  // Pre-stabilisation: contacts on the start positions, applied to x and p alike (uses tmp).
  static void stabilize(const Exec& ex, const SimViews& S);
};

}  // namespace seamless::kernels
