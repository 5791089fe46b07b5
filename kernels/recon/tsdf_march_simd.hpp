// The CPU's march of 8 rays at once on SIMD lanes (defined in tsdf_march_simd.cpp, compiled for
// AVX2 where simd::cpu_simd() finds it at run time). Never seen by nvcc.
//
// The raycast's work item on the CPU is then a row of a ray group (8 neighbouring pixels, which
// mostly march alike: docs/PERFORMANCE.md, "The CPU's march on SIMD lanes"), lane l the ray of
// pixel l. Each lane runs march_ray's operations in march_ray's order (tsdf_march.hpp; no FMA
// contraction: core/simd.hpp) until its own ray ends, so it takes the same samples and finds the
// same hit as the scalar loop, bit for bit (tests compare both). A step of the scalar march is a
// chain of dependent loads and about two hundred instructions, one ray after the other; on lanes
// the arithmetic is shared by 8 rays and their voxel loads go out together as gathers.
#pragma once
#if !defined(__CUDACC__)
#include "core/cpu_simd.hpp"
#include "kernels/recon/tsdf_march.hpp"

namespace seamless::kernels {

// Whether march_row_simd can take rays through a: it needs the block window, and reaches its
// entries with 32-bit indices.
inline bool simd_marchable(const WindowedHashAccess& a) {
  return a.window.index && a.window.count() < (std::int64_t{1} << 31);
}

SEAMLESS_SIMD_TARGET_BEGIN
namespace detail {
// The rays of pixels (x0 + l, y), l < n <= 8, into r[l] (what pixel_ray gives), marched as
// march_ray marches them: hit[l] and zh[l] are what march_ray returns and writes for ray r[l] (zh[l]
// is left unspecified where there is no hit).
void march_row_simd(const WindowedHashAccess& a, int x0, int y, int n, const Intrinsics& K, const SE3& world_T_camera,
                    float min_depth, float max_depth, const RayIntervals& iv, PixelRay* r, bool* hit, float* zh);

// pixel_normal (tsdf_march.hpp) of pixels (x0 + l, y), l < n <= 8, into normal(x0 + l, y), with its
// expressions in its order on the lanes: the same normals bit for bit.
void normals_row_simd(View2D<const vec3> vtx, View2D<const float> depth, int x0, int y, int n, vec3 eye,
                      float jump_per_metre, View2D<vec3> normal);
}  // namespace detail
SEAMLESS_SIMD_TARGET_END

}  // namespace seamless::kernels
#endif
