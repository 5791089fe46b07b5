// Kernel family of the integration steps after the constraints (solver.hpp lists the passes in
// order): velocities from positions, and the sorted state back to the slots.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "kernels/physics/sim_views.hpp"

namespace seamless::kernels {

template <Executor Exec> struct Integration {
  // v = v_pred + (p - p0) / dt (exactly symplectic Euler when nothing acted), restitution, sleeping.
  static void update_velocity(const Exec& ex, const SimViews& S);
  // x, v back to id order; counters[4] = bits of the largest |v|^2 (reset by predict).
  static void write_back(const Exec& ex, const SimViews& S);
  static void slots_to_ids(const Exec& ex, const SimViews& S, vec3* x_id, std::uint32_t* phase_id);
};

}  // namespace seamless::kernels
