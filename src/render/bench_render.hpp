// `seamless bench render`: frame time of the renderer at 1920x1080 with 1,000,000 fluid
// particles drawn by screen-space fluid rendering through headless EGL (goal on the GPU
// machine: at most 4 ms per frame). The particles are a block of fluid on a lattice in front of
// a tilted plane scene mesh, viewed obliquely, so that every pass has work across the screen.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "render/renderer.hpp"

namespace seamless {

struct RenderBenchResult {
  int width = 0, height = 0;
  std::int64_t particles = 0;
  int frames = 0;
  double median_frame_ms = 0.0;  // upload from host + draw + glFinish (no readback), wall clock
  double median_draw_ms = 0.0;   // draw + glFinish with the particles already in GL buffers
                                 // (the CUDA-OpenGL interop path: no host upload)
  double median_readback_ms = 0.0;
  double median_gpu_ms = 0.0;         // GPU time of the draw-only frame: first to last timestamp query
  double median_interop_ms = -1.0;    // CUDA device copy into GL + draw + glFinish; -1: not measured
                                      // (no CUDA, or the GL context is not on the CUDA device)
  double median_ellipsoid_ms = -1.0;  // the anisotropic kernels (FluidEllipsoids) on ellipsoid_device,
  std::string ellipsoid_device;       // wall time with synchronisation; -1: spheres drawn
  std::vector<RenderTiming> passes;   // GPU time per pass, median over the frames
  std::string gl_renderer;
};

// `settings` gives the fluid pass settings (render.thickness_downsample, depth_prepass, ...); its
// width and height are replaced by the arguments.
RenderBenchResult bench_render(int width = 1920, int height = 1080, std::int64_t particles = 1'000'000, int frames = 20,
                               const RenderParams& settings = {});
// The settings before the speed remedies (raster sprites, full-resolution thickness, no depth
// prepass, two bilateral passes with every tap, unclamped sprites), for comparison.
RenderParams unoptimised_render_settings();

}  // namespace seamless
