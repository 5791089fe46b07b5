// Kernel family of the solids: rigid bodies by shape matching and cloth constraints (solver.hpp
// lists the passes in order). A new constraint type of a solid goes here: its math in
// constraints.hpp, its pass a member below.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

template <Executor Exec> struct Solids {
  // Shape matching of every rigid body (Mueller 2005): per-body sums, rotation, goal positions.
  static void shape_match(const Exec& ex, const SimViews& S);
  // Static friction of each rigid body as a whole, after shape_match (solids.inl).
  static void body_static_friction(const Exec& ex, const SimViews& S);
  // Cloth stretch and bending (Mueller 2007); writes tmp.
  // Stretch constraints, colour after colour (edges [colour_off[c], colour_off[c + 1]), colour_off
  // on the host), in place.
  static void cloth_stretch(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours);
  // Strain limiting (Provot 1995): `passes` sweeps over the colours, in place.
  static void cloth_strain_limit(const Exec& ex, const SimViews& S, const std::int64_t* colour_off, int colours,
                                 int passes);
  static void cloth_bend(const Exec& ex, const SimViews& S);
};

}  // namespace seamless::kernels
