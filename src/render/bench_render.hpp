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
  double median_frame_ms = 0.0;   // upload from host + draw + glFinish (no readback), wall clock
  double median_draw_ms = 0.0;    // draw + glFinish with the particles already in GL buffers
                                  // (the CUDA-OpenGL interop path: no host upload)
  double median_readback_ms = 0.0;
  std::vector<RenderTiming> passes;  // GPU time per pass, median over the frames
  std::string gl_renderer;
};

RenderBenchResult bench_render(int width = 1920, int height = 1080, std::int64_t particles = 1'000'000,
                               int frames = 20);

}  // namespace seamless
