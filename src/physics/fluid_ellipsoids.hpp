// The fluid's anisotropic kernels (kernels/physics/anisotropy.hpp) for particles anywhere: the
// grid of cells that the kernel searches, built from the positions given (the solver's state
// between steps, a particle file, a benchmark's block), on the device they are on.
//
//   FluidEllipsoids shapes(Device::CUDA);
//   const vec4* e = shapes.compute(d_x, d_phase, n, sphere_radius, h);  // 3 vec4 per particle
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/math.hpp"
#include "kernels/physics/anisotropy.hpp"
#include "kernels/physics/particle_math.hpp"

namespace seamless {

class FluidEllipsoids {
 public:
  // vec4 per particle (the layout: kernels/physics/anisotropy.hpp).
  static constexpr int kVec4s = kernels::kEllipsoidVec4s;
  // The neighbourhood h in particle radii (Yu & Turk's two rest spacings).
  static constexpr float kNeighbourhoodRadii = kernels::kNeighbourhoodRadii;
  // The longest axis an ellipsoid can have, in sphere radii: two axes at the clamp
  // (kernels::kMaxAxisRatio times shorter than the third) and the sphere's volume kept.
  static float longest_axis() { return std::cbrt(kernels::kMaxAxisRatio * kernels::kMaxAxisRatio); }

  explicit FluidEllipsoids(Device d);

  // The ellipsoids of the n particles at x with phases `phase` (id order, both on device()): for
  // each fluid particle (phase::kFluid) the one shaped by its fluid neighbours within h, of the
  // volume of the sphere of `radius`; for the others that sphere. kernels::kEllipsoidVec4s vec4
  // per particle, on device(), valid until the next call.
  const vec4* compute(const vec3* x, const std::uint32_t* phase, std::int64_t n, float radius, float h);
  // The same for host arrays (copied to device() and back): the tests' and the renderer's CPU path.
  std::vector<vec4> compute_host(const std::vector<vec3>& x, const std::vector<std::uint32_t>& phase, float radius,
                                 float h);
  Device device() const { return dev_; }

 private:
  Device dev_;
  Buffer<std::uint32_t> keys_;
  Buffer<int> id_, cell_start_;
  Buffer<kernels::Packed> sorted_;
  Buffer<vec4> out_;
  Buffer<vec3> x_;  // compute_host's copies
  Buffer<std::uint32_t> phase_;
};

}  // namespace seamless
