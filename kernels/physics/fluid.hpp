// Kernel family of the fluid (position based fluids, Macklin & Mueller 2013) and the velocity
// effects (solver.hpp lists the passes in order).
#pragma once
#include "core/exec.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

template <Executor Exec> struct Fluid {
  // Fluid density and lambda (PBF eqs. 1-11); number of active contacts of every particle.
  static void prepare_constraints(const Exec& ex, const SimViews& S);
  // Contacts (particles, static particles, SDF) with friction, plus the PBF position update
  // (eq. 12/14); writes tmp = sp + correction.
  static void solve_contacts_fluid(const Exec& ex, const SimViews& S);
  // XSPH viscosity, vorticity confinement, Akinci cohesion and surface tension, cloth
  // aerodynamics; writes vtmp.
  static void velocity_effects(const Exec& ex, const SimViews& S, bool has_fluid);
};

}  // namespace seamless::kernels
