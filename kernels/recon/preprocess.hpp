// Depth preprocessing after KinectFusion (Newcombe et al. 2011, section 3.2): bilateral filter,
// a pyramid that averages only across similar depths, vertex and normal maps. Depth is in metres,
// 0 = no reading; an invalid vertex or normal is the zero vector.
#pragma once
#include "core/camera.hpp"
#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

template <Executor Exec> struct Preprocess {
  // Edge-preserving smoothing of depth (KinectFusion eq. 2): Gaussian weights in pixel distance
  // (sigma_space, pixels) and in depth difference (sigma_depth, metres) over a (2r+1)^2 window.
  static void bilateral_filter(const Exec& ex, View2D<const float> depth, View2D<float> out, float sigma_space,
                               float sigma_depth, int radius);

  // Half resolution: mean of the 2x2 block's valid depths within max_diff of the block's first
  // valid depth, so that averaging never bridges a depth discontinuity.
  static void pyr_down_depth(const Exec& ex, View2D<const float> in, View2D<float> out, float max_diff);

  // Half resolution intensity (plain 2x2 mean) for a photometric tracker's pyramid. A negative
  // intensity is no reading (kernels/recon/rgbd.hpp, kNoIntensity): a block with one has none either
  // (-1), so no coarse pixel mixes the undistortion border's missing colour into real colour.
  static void pyr_down_intensity(const Exec& ex, View2D<const float> in, View2D<float> out);

  // Back-projects every valid depth pixel through the pinhole model (camera coordinates).
  static void depth_to_vertices(const Exec& ex, View2D<const float> depth, Intrinsics K, View2D<vec3> vertices);

  // Normal from the cross product of the forward differences to the right and down neighbours,
  // oriented towards the camera (KinectFusion eq. 3). Invalid where a neighbour is missing or the
  // neighbours are further apart than max_edge metres (a depth discontinuity).
  static void vertices_to_normals(const Exec& ex, View2D<const vec3> vertices, View2D<vec3> normals, float max_edge);
};

}  // namespace seamless::kernels
