// CUDA-OpenGL interop for the particle buffers (only with SEAMLESS_HAS_CUDA): the solver's
// device positions and phases are copied device-to-device into the renderer's GL vertex
// buffers, so a frame needs no trip through host memory; with the anisotropic kernels on, the
// fluid's ellipsoids are computed on the device (FluidEllipsoids) and copied likewise. On the CPU
// backend the renderer's plain upload (Renderer::draw with host spans) is used instead.
//
//   CudaGlParticles interop(renderer, capacity);          // after the GL context exists
//   interop.copy_from_device(d_x, d_phase, n, radius);    // each frame
//   renderer.draw_device_particles(list_without_positions, n, camera);
//
// Untested here (no GPU in CI): the lead runs it on the GPU machine. The GL context and the CUDA
// device must be on the same GPU (NVIDIA's EGL device display, see gl_context.hpp).
#pragma once
#include "seamless/build_config.hpp"

#if SEAMLESS_HAS_CUDA
#include <cstdint>

#include "core/math.hpp"
#include "physics/fluid_ellipsoids.hpp"

namespace seamless {

class Renderer;

class CudaGlParticles {
 public:
  // Grows the renderer's particle buffers to `capacity` and registers them with CUDA.
  CudaGlParticles(Renderer& r, std::int64_t capacity);
  ~CudaGlParticles();
  CudaGlParticles(const CudaGlParticles&) = delete;
  CudaGlParticles& operator=(const CudaGlParticles&) = delete;

  // Copies n particles (n <= capacity) of the given radius from device memory, and their
  // ellipsoids when the renderer draws them (Renderer::fluid_ellipsoid_sizes); on the default stream.
  void copy_from_device(const vec3* d_x, const std::uint32_t* d_phase, std::int64_t n, float particle_radius);
  std::int64_t capacity() const { return capacity_; }

 private:
  Renderer& renderer_;
  void* res_[3] = {nullptr, nullptr, nullptr};  // cudaGraphicsResource_t of positions, phases, ellipsoids
  std::int64_t capacity_ = 0;
  FluidEllipsoids shapes_{Device::CUDA};
};

}  // namespace seamless
#endif
