// Kernel family of the fluid's anisotropic kernels (Yu & Turk 2013, "Reconstructing surfaces of
// particle-based fluids using anisotropic kernels", section 4): each fluid particle's ellipsoid,
// shaped like its neighbourhood, for the renderer's splats (src/render/shaders/splat.glsl).
// Particles spread over a surface have their neighbours in a plane, so their ellipsoids flatten
// into overlapping discs: one flat sheet where spheres a few radii apart leave a bump per particle
// and a hole between them. Inside a body of water the neighbourhood is isotropic and the ellipsoid
// stays the sphere. The host side (the grid it searches, the buffers) is
// src/physics/fluid_ellipsoids.hpp.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/math.hpp"
#include "kernels/physics/particle_math.hpp"

namespace seamless::kernels {

// Yu & Turk's constants (section 4): an axis at most kMaxAxisRatio times shorter than the longest;
// the neighbourhood h twice the particle spacing, which at rest is two radii: kNeighbourhoodRadii
// radii. Their N_eps (25) neighbours for a shape is what that h holds in bulk (about 33); here the
// count must also hold for a layer spread over a surface, whose particles lie up to 3 radii apart,
// so that within h a particle inside the layer has its first ring (about 6) and one at the
// layer's edge half of it. Three neighbours span a plane, the least a flattened shape needs: with
// fewer a particle stays a sphere (a lone drop, the tip of a filament).
constexpr float kMaxAxisRatio = 4.f;
constexpr float kNeighbourhoodRadii = 4.f;
constexpr int kMinNeighbours = 3;
// Their smoothing of the kernel centres towards the neighbourhood's weighted mean (section 5,
// lambda = 0.9 in the paper): it flattens a layer whose particles lie at slightly different
// heights. Kept below theirs because their centres feed an isosurface while ours are drawn
// directly, and a puddle's rim would shrink by most of a neighbourhood.
constexpr float kCentreSmoothing = 0.5f;

// One particle's ellipsoid as the splats read it, 3 vec4 per particle id:
//   [0] centre (xyz) and the longest semi-axis (w, the splat's screen bound);
//   [1] M00 M01 M02 M11, [2] M12 M22 lone offset: the symmetric M of the ellipsoid
//   (x - c)^T M (x - c) <= 1; lone: 1 for a lone fluid particle (fewer than kMinNeighbours fluid
//   neighbours: the renderer draws it as a drop of its own size), else 0; offset: how far the
//   neighbours' weighted mean (eq. 10's) lies from the particle, in units of h: about 0 inside a
//   body of fluid, whose neighbourhoods are complete on every side, and a fifth of h or more at a
//   free surface (the usual surface test of SPH particles, e.g. Solenthaler, Schlaefli & Pajarola
//   2007); 1 for a lone particle or one that is not fluid. The renderer's depth splat draws the
//   particles of large offset first, as occluders (src/render/shaders/ssfr_depth_splat.comp).
constexpr int kEllipsoidVec4s = 3;

struct EllipsoidViews {
  std::int64_t n = 0;               // particles (all phases)
  const Packed* sorted = nullptr;   // (position, phase bits) in cell order
  const int* id = nullptr;          // cell order -> particle id
  GridSpec grid{};                  // cells of h / 2 (GridSpec::for_radius(h, bits))
  const int* cell_start = nullptr;  // NeighbourGrid::cell_starts of the sorted keys
  std::uint32_t fluid_mask = 0;     // phase bits of the particles that are fluid
  float radius = 0.f;               // the sphere drawn for an isotropic neighbourhood, metres
  float h = 0.f;                    // neighbourhood radius, metres
  vec4* ellipsoids = nullptr;       // out: kEllipsoidVec4s per particle id
};

template <Executor Exec> struct Anisotropy {
  // sorted[s] = (x[id[s]], phase[id[s]]): the positions and phases in cell order, packed.
  static void pack(const Exec& ex, const vec3* x, const std::uint32_t* phase, const int* id, std::int64_t n,
                   Packed* sorted);
  // Every particle's ellipsoid: fluid particles from their fluid neighbours within h, the others
  // (and fluid particles with fewer than kMinNeighbours) the sphere of the given radius.
  static void ellipsoids(const Exec& ex, const EllipsoidViews& V);
};

}  // namespace seamless::kernels
