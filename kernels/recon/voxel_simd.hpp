// A block row's voxels on 8 SIMD lanes (the CPU's fusion and march on lanes,
// tsdf_fusion_simd.cpp and tsdf_march_simd.cpp): the 4-byte Voxel of voxel_hash.hpp unpacked to
// its distance in snorm16 steps and its weight, and packed back, with the scalar helpers'
// expressions (voxel_observed, voxel_weight, sdf_steps), so the lanes keep their values bit for
// bit. Included inside a SEAMLESS_SIMD_TARGET region. Never seen by nvcc.
#pragma once
#if !defined(__CUDACC__)
#include "core/simd.hpp"
#include "kernels/recon/voxel_hash.hpp"

namespace seamless::kernels::detail {

static_assert(sizeof(Voxel) == sizeof(std::int32_t) && alignof(Voxel) <= alignof(std::int32_t));

// Lane l: voxel l as one 32-bit word, the distance in its low half and the weight in its high half
// (Voxel's member order on a little-endian host).
SEAMLESS_SIMD_INL simd::vf voxel_steps(simd::i8 raw) { return __builtin_convertvector((raw << 16) >> 16, simd::f8); }
SEAMLESS_SIMD_INL simd::i8 voxel_weights(simd::i8 raw) {
  typedef unsigned u8 __attribute__((vector_size(32)));
  return reinterpret_cast<simd::i8>(reinterpret_cast<u8>(raw) >> 16);
}
// The words of voxels whose distance is steps (whole numbers in [-32767, 32767]) and weight wt.
SEAMLESS_SIMD_INL simd::i8 pack_voxels(simd::i8 steps, simd::i8 wt) { return (steps & 0xffff) | (wt << 16); }

// sdf_steps lane by lane: clamped to the truncation, then rounded to nearest with ties away from
// zero (the truncating conversion of steps +- 1/2).
SEAMLESS_SIMD_INL simd::i8 sdf_steps(simd::vf steps) {
  using simd::vf, simd::select;
  steps = select(steps >= vf(-kSdfSteps), select(steps <= vf(kSdfSteps), steps, vf(kSdfSteps)), vf(-kSdfSteps));
  const simd::i8 sign = reinterpret_cast<simd::i8>(steps.v) & static_cast<std::int32_t>(0x80000000u);
  const simd::f8 half = reinterpret_cast<simd::f8>(reinterpret_cast<simd::i8>(vf(0.5f).v) | sign);
  return __builtin_convertvector(steps.v + half, simd::i8);
}

}  // namespace seamless::kernels::detail
#endif
