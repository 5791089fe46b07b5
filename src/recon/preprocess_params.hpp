// Depth preprocessing settings (KinectFusion, Newcombe et al. 2011, section 3.2).
#pragma once
#include "core/params.hpp"

namespace seamless {

struct PreprocessParams {
  bool bilateral = true;
  float sigma_space = 4.5f;          // pixels
  float sigma_depth = 0.03f;         // metres
  int radius = 3;                    // window (2r+1)^2
  bool bilateral_inline_exp = true;  // range weights from kernels::exp_nonpositive instead of expf
  float pyramid_max_diff = 0.09f;    // 3 sigma_depth: averaging never bridges larger jumps
  float max_normal_edge = 0.1f;      // metres; longer neighbour edges are depth discontinuities
  int levels = 3;

  template <class V> void visit(V& v) {
    v("bilateral", bilateral,
      "smooth depth with the bilateral filter before tracking. Off, the frame's normals come from the raw "
      "depth, whose steps (a Kinect v1's: about 3 mm at 1 m, against 2 mm between pixels) turn them by tens of "
      "degrees: the trackers' normal test then rejects most pixels, and frame-to-model tracking loses nearly "
      "every frame of tum_fr1_rpy");
    v("sigma_space", sigma_space, "bilateral spatial sigma, pixels", Range{0.1, 50});
    v("sigma_depth", sigma_depth, "bilateral depth sigma, metres", Range{0.001, 1});
    v("radius", radius, "bilateral window radius, pixels", Range{1, 15});
    v("bilateral_inline_exp", bilateral_inline_exp,
      "bilateral range weights from an inlined exp (~2 ulp; vectorised on the CPU, 6x fewer filter "
      "instructions) instead of libm's expf (false: the old filter, bit for bit); the filtered depth differs "
      "in its last bits. On CUDA both values evaluate the same expf");
    v("pyramid_max_diff", pyramid_max_diff, "largest depth difference averaged in the pyramid, metres",
      Range{0.001, 1});
    v("max_normal_edge", max_normal_edge, "neighbour distance beyond which no normal is computed, metres",
      Range{0.001, 1});
    v("levels", levels, "pyramid levels", Range{1, 5});
  }
};

}  // namespace seamless
