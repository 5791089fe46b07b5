// CUDA-OpenGL interop for the particle buffers (only with SEAMLESS_HAS_CUDA): the solver's
// device positions and phases are copied device-to-device into the renderer's GL vertex
// buffers, so a frame needs no trip through host memory. On the CPU backend the renderer's
// plain upload (Renderer::draw with host spans) is used instead.
//
//   CudaGlParticles interop(renderer, capacity);          // after the GL context exists
//   interop.copy_from_device(d_x, d_phase, n);            // each frame
//   renderer.draw_device_particles(list_without_positions, n, camera);
//
// Untested here (no GPU in CI): the lead runs it on the GPU machine. The GL context and the CUDA
// device must be on the same GPU (NVIDIA's EGL device display, see gl_context.hpp).
#pragma once
#include "seamless/build_config.hpp"

#if SEAMLESS_HAS_CUDA
#include <cstdint>

#include "core/math.hpp"

namespace seamless {

class Renderer;

class CudaGlParticles {
 public:
  // Grows the renderer's particle buffers to `capacity` and registers them with CUDA.
  CudaGlParticles(Renderer& r, std::int64_t capacity);
  ~CudaGlParticles();
  CudaGlParticles(const CudaGlParticles&) = delete;
  CudaGlParticles& operator=(const CudaGlParticles&) = delete;

  // Copies n particles (n <= capacity) from device memory; stream 0 = the default stream.
  void copy_from_device(const vec3* d_x, const std::uint32_t* d_phase, std::int64_t n, void* stream = nullptr);
  std::int64_t capacity() const { return capacity_; }

 private:
  void* res_[2] = {nullptr, nullptr};  // cudaGraphicsResource_t of positions, phases
  std::int64_t capacity_ = 0;
};

}  // namespace seamless
#endif
