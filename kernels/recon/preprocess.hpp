// Depth preprocessing after KinectFusion (Newcombe et al. 2011, section 3.2): bilateral filter,
// a pyramid that averages only across similar depths, vertex and normal maps. Depth is in metres,
// 0 = no reading; an invalid vertex or normal is the zero vector.
#pragma once
#include "core/intrinsics.hpp"
#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// e^x for x <= 0, inlined and branch-free, so that the CPU's bilateral filter can evaluate it for
// 8 pixels at once in vector registers (libm's expf is a call per tap: a third of the filter's
// instructions). e^x = 2^k e^r with k = round(x log2 e) and r = x - k ln 2 (Cody and Waite 1980:
// ln 2 split in two, the first part with few enough bits that k ln2_hi is exact, so r is exact to
// about an ulp of r), |r| <= ln 2 / 2; e^r by its Taylor series to degree 7, whose remainder is
// below (ln 2 / 2)^8 / 8! ~ 5e-9. The Horner steps' roundings make it ~2 ulp, relative error at
// most 3e-7 (ExpNonpositive.RelativeErrorBound checks that bound against double exp). Below -87
// (e^-87 ~ 1.6e-38, the smallest normal float) and for NaN it returns 0, where expf would return
// a denormal: 2^k must stay a normal float.
SEAMLESS_HD inline float exp_nonpositive(float x) {
#ifdef __CUDA_ARCH__
  return expf(x);  // a handful of instructions on the GPU (ex2.approx): the polynomial was slower
#else
  const bool normal = x >= -87.f;
  const float xc = normal ? x : -87.f;
  // Round to nearest by adding 1.5 * 2^23: the float's spacing there is 1, so the sum's low
  // mantissa bits hold k (|k| <= 126); two additions instead of floorf, which is a libm call or a
  // dozen instructions without SSE4.1's roundss, and does not vectorise.
  constexpr float kShift = 12582912.f;
  const float shifted = xc * 1.44269504f + kShift;
  const float kf = shifted - kShift;
  const float r = (xc - kf * 0.693145751953125f) - kf * 1.428606765330187e-6f;
  float p = 1.f / 5040.f;
  p = p * r + 1.f / 720.f;
  p = p * r + 1.f / 120.f;
  p = p * r + 1.f / 24.f;
  p = p * r + 1.f / 6.f;
  p = p * r + 0.5f;
  p = p * r + 1.f;
  p = p * r + 1.f;
  const float two_k = bits_float((float_bits(shifted) - float_bits(kShift) + 127) << 23);  // k in [-126, 0]
  return normal ? p * two_k : 0.f;
#endif
}

template <Executor Exec> struct Preprocess {
  // Edge-preserving smoothing of depth (KinectFusion eq. 2): Gaussian weights in pixel distance
  // (sigma_space, pixels) and in depth difference (sigma_depth, metres) over a (2r+1)^2 window.
  // The weight is expf of the Gaussians' summed exponent, or with inline_exp exp_nonpositive of the
  // same float argument (vectorised on the CPU: preprocess.bilateral_inline_exp), which differs
  // from expf by a few ulp of each weight (PreprocessBilateral.MatchesExactFormula bounds both).
  static void bilateral_filter(const Exec& ex, View2D<const float> depth, View2D<float> out, float sigma_space,
                               float sigma_depth, int radius, bool inline_exp = false);

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
