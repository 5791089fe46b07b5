// CUDA-OpenGL interop (see cuda_interop.hpp). Compiled as C++ against the CUDA runtime; this file
// must not include epoxy (cuda_gl_interop.h brings its own GL declarations).
#include "render/cuda_interop.hpp"

#include <cuda_gl_interop.h>

#include <string>

#include "core/cuda_check.hpp"
#include "core/error.hpp"
#include "render/renderer.hpp"

namespace seamless {

CudaGlParticles::CudaGlParticles(Renderer& r, std::int64_t capacity) : capacity_(capacity) {
  r.reserve_particles(capacity);  // reallocation after registration would invalidate it
  const unsigned bufs[2] = {r.particle_position_buffer(), r.particle_phase_buffer()};
  for (int i = 0; i < 2; ++i) {
    cudaGraphicsResource_t res = nullptr;
    SEAMLESS_CUDA_CHECK(cudaGraphicsGLRegisterBuffer(&res, bufs[i], cudaGraphicsRegisterFlagsWriteDiscard));
    res_[i] = res;
  }
}

CudaGlParticles::~CudaGlParticles() {
  for (void* res : res_)
    if (res) cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(res));
}

void CudaGlParticles::copy_from_device(const vec3* d_x, const std::uint32_t* d_phase, std::int64_t n, void* stream) {
  if (n > capacity_)
    throw Error("render: " + std::to_string(n) + " particles exceed the interop capacity " + std::to_string(capacity_));
  auto s = static_cast<cudaStream_t>(stream);
  cudaGraphicsResource_t res[2] = {static_cast<cudaGraphicsResource_t>(res_[0]),
                                   static_cast<cudaGraphicsResource_t>(res_[1])};
  SEAMLESS_CUDA_CHECK(cudaGraphicsMapResources(2, res, s));
  void* dst[2] = {nullptr, nullptr};
  std::size_t bytes = 0;
  for (int i = 0; i < 2; ++i) SEAMLESS_CUDA_CHECK(cudaGraphicsResourceGetMappedPointer(&dst[i], &bytes, res[i]));
  const auto un = static_cast<std::size_t>(n);
  SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(dst[0], d_x, un * sizeof(vec3), cudaMemcpyDeviceToDevice, s));
  SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(dst[1], d_phase, un * sizeof(std::uint32_t), cudaMemcpyDeviceToDevice, s));
  SEAMLESS_CUDA_CHECK(cudaGraphicsUnmapResources(2, res, s));
}

}  // namespace seamless
