// Depth preprocessing after KinectFusion (Newcombe et al. 2011, section 3.2): bilateral filter,
// a pyramid that averages only across similar depths, vertex and normal maps. Depth is in metres,
// 0 = no reading; an invalid vertex or normal is the zero vector.
#pragma once
#include "core/camera.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// e^x for x <= 0, inlined (the bilateral filter's range weight: 49 per pixel at radius 3, where a call to libm's expf
// was a fifth of a CPU frame). e^x = 2^k 2^f with k = round(x log2 e), |f| <= 1/2; 2^f = e^(f ln 2)
// by its Taylor series to degree 6, whose remainder (0.347^7 / 7! ~ 1.2e-7) is float precision.
// Below -87 (e^-87 ~ 1.6e-38, the smallest normal float) it returns 0, as expf's underflow does.
SEAMLESS_HD inline float exp_nonpositive(float x) {
  if (!(x >= -87.f)) return 0.f;
  // Round to nearest by adding 1.5 * 2^23: the float's spacing there is 1, so the sum's low
  // mantissa bits hold k (|k| <= 126); two additions instead of floorf (a libm call or a
  // dozen instructions without SSE4.1's roundss).
  const float shifted = x * 1.44269504f + 12582912.f;
  const float kf = shifted - 12582912.f;
  const float r = x - kf * 0.693147181f;  // e^r with |r| <= ln 2 / 2
  float p = 1.f / 720.f;
  p = p * r + 1.f / 120.f;
  p = p * r + 1.f / 24.f;
  p = p * r + 1.f / 6.f;
  p = p * r + 0.5f;
  p = p * r + 1.f;
  p = p * r + 1.f;
  return p * bits_float((float_bits(shifted) - float_bits(12582912.f) + 127) << 23);  // 2^k, k in [-126, 0]
}

// Edge-preserving smoothing of depth (KinectFusion eq. 2): Gaussian weights in pixel distance
// (sigma_space, pixels) and in depth difference (sigma_depth, metres) over a (2r+1)^2 window.
template <class Exec>
void bilateral_filter(const Exec& ex, View2D<const float> depth, View2D<float> out, float sigma_space,
                      float sigma_depth, int radius);

// Half resolution: mean of the 2x2 block's valid depths within max_diff of the block's first
// valid depth, so that averaging never bridges a depth discontinuity.
template <class Exec>
void pyr_down_depth(const Exec& ex, View2D<const float> in, View2D<float> out, float max_diff);

// Half resolution intensity (plain 2x2 mean) for a photometric tracker's pyramid. A negative
// intensity is no reading (kernels/recon/rgbd.hpp, kNoIntensity): a block with one has none either
// (-1), so no coarse pixel mixes the undistortion border's missing colour into real colour.
template <class Exec>
void pyr_down_intensity(const Exec& ex, View2D<const float> in, View2D<float> out);

// Back-projects every valid depth pixel through the pinhole model (camera coordinates).
template <class Exec>
void depth_to_vertices(const Exec& ex, View2D<const float> depth, Intrinsics K, View2D<vec3> vertices);

// Normal from the cross product of the forward differences to the right and down neighbours,
// oriented towards the camera (KinectFusion eq. 3). Invalid where a neighbour is missing or the
// neighbours are further apart than max_edge metres (a depth discontinuity).
template <class Exec>
void vertices_to_normals(const Exec& ex, View2D<const vec3> vertices, View2D<vec3> normals, float max_edge);

}  // namespace seamless::kernels
