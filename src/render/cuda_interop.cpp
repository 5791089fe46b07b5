// CUDA-OpenGL interop (see cuda_interop.hpp). Compiled as C++ against the CUDA runtime; this file
// must not include epoxy (cuda_gl_interop.h brings its own GL declarations).
#include "render/cuda_interop.hpp"

#include <cuda_gl_interop.h>

#include <optional>
#include <string>

#include "core/cuda_check.hpp"
#include "core/error.hpp"
#include "render/renderer.hpp"

namespace seamless {

CudaGlParticles::CudaGlParticles(Renderer& r, std::int64_t capacity) : renderer_(r), capacity_(capacity) {
  r.reserve_particles(capacity);  // reallocation after registration would invalidate it
  const unsigned bufs[3] = {r.particle_position_buffer(), r.particle_phase_buffer(), r.particle_ellipsoid_buffer()};
  for (int i = 0; i < 3; ++i) {
    cudaGraphicsResource_t res = nullptr;
    SEAMLESS_CUDA_CHECK(cudaGraphicsGLRegisterBuffer(&res, bufs[i], cudaGraphicsRegisterFlagsWriteDiscard));
    res_[i] = res;
  }
}

CudaGlParticles::~CudaGlParticles() {
  for (void* res : res_)
    if (res) cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(res));
}

void CudaGlParticles::copy_from_device(const vec3* d_x, const std::uint32_t* d_phase, std::int64_t n,
                                       float particle_radius) {
  if (n > capacity_)
    throw Error("render: " + std::to_string(n) + " particles exceed the interop capacity " + std::to_string(capacity_));
  const std::optional<Renderer::EllipsoidSizes> sizes = renderer_.fluid_ellipsoid_sizes(particle_radius);
  const vec4* d_ell = sizes && n > 0 ? shapes_.compute(d_x, d_phase, n, sizes->radius, sizes->h) : nullptr;
  const int maps = d_ell ? 3 : 2;
  cudaGraphicsResource_t res[3] = {static_cast<cudaGraphicsResource_t>(res_[0]),
                                   static_cast<cudaGraphicsResource_t>(res_[1]),
                                   static_cast<cudaGraphicsResource_t>(res_[2])};
  SEAMLESS_CUDA_CHECK(cudaGraphicsMapResources(maps, res, nullptr));
  void* dst[3] = {nullptr, nullptr, nullptr};
  std::size_t bytes = 0;
  for (int i = 0; i < maps; ++i) SEAMLESS_CUDA_CHECK(cudaGraphicsResourceGetMappedPointer(&dst[i], &bytes, res[i]));
  const auto un = static_cast<std::size_t>(n);
  SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(dst[0], d_x, un * sizeof(vec3), cudaMemcpyDeviceToDevice, nullptr));
  SEAMLESS_CUDA_CHECK(cudaMemcpyAsync(dst[1], d_phase, un * sizeof(std::uint32_t), cudaMemcpyDeviceToDevice, nullptr));
  if (d_ell)
    SEAMLESS_CUDA_CHECK(
        cudaMemcpyAsync(dst[2], d_ell, un * FluidEllipsoids::kVec4s * sizeof(vec4), cudaMemcpyDeviceToDevice, nullptr));
  SEAMLESS_CUDA_CHECK(cudaGraphicsUnmapResources(maps, res, nullptr));
  renderer_.use_device_ellipsoids(d_ell != nullptr);
}

}  // namespace seamless
