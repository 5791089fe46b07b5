// Kernel bodies for raycasting in recon/tsdf.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/tsdf.hpp"

namespace seamless::kernels {

// Ray parameter at which the ray o + t d (voxel units) leaves block b (slab method).
SEAMLESS_HD inline float block_exit(vec3 o, vec3 d, int3 b) {
  float t = 1e30f;
  float lo[3] = {b.x * 8.f, b.y * 8.f, b.z * 8.f};
  float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z};
  for (int k = 0; k < 3; ++k) {
    if (dd[k] > 0.f) t = fminf(t, (lo[k] + 8.f - oo[k]) / dd[k]);
    if (dd[k] < 0.f) t = fminf(t, (lo[k] - oo[k]) / dd[k]);
  }
  return t;
}

// Regula falsi on the trilinear field between a positive sample at ta and a negative one at tb.
template <class Acc>
SEAMLESS_HD inline float refine_crossing(const Acc& a, vec3 o, vec3 d, float ta, float fa, float tb, float fb,
                                         BlockCache& c) {
  for (int it = 0; it < 3; ++it) {
    float tm = ta + (tb - ta) * fa / (fa - fb);
    float fm;
    if (!sample_tsdf(a, o + d * tm, c, &fm)) return tm;
    if (fm > 0.f) ta = tm, fa = fm;
    else tb = tm, fb = fm;
  }
  return ta + (tb - ta) * fa / (fa - fb);
}

template <class Acc>
SEAMLESS_HD inline void raycast_pixel(const Acc& a, int x, int y, const Intrinsics& K, const SE3& world_T_camera,
                                      float min_depth, float max_depth, const RaycastOutput& out) {
  out.depth(x, y) = 0.f;
  out.vertex(x, y) = out.normal(x, y) = {0.f, 0.f, 0.f};
  out.color(x, y) = {0, 0, 0};
  const VoxelGeometry& g = a.geom;
  // Ray in voxel units, parametrised by camera depth z: point(z) = o + d z.
  vec3 dir_c = K.unproject(static_cast<float>(x), static_cast<float>(y), 1.f);
  vec3 o = g.to_voxel(world_T_camera.t);
  vec3 d = world_T_camera.rotate(dir_c) / g.voxel_size;
  const float dlen = length(d);  // voxels per metre of depth
  const float min_step = 0.5f / dlen;  // half a voxel
  BlockCache c;
  float z = min_depth, z_prev = 0.f, f_prev = 0.f;
  bool have_prev = false;
  for (int it = 0; it < 8192 && z < max_depth; ++it) {
    vec3 q = o + d * z;
    int3 b = block_of_voxel(floor_to_int(q));
    if (!(b == c.block)) {
      c.block = b;
      c.index = a.find_block(b);
    }
    if (c.index < 0) {  // empty space: skip the whole block (Niessner section 4.3)
      z = fmaxf(block_exit(o, d, b), z) + min_step * 0.1f;
      have_prev = false;
      continue;
    }
    float f;
    if (!sample_tsdf(a, q, c, &f)) {
      z += min_step;
      have_prev = false;
      continue;
    }
    if (have_prev && f_prev > 0.f && f <= 0.f) {
      float zh = refine_crossing(a, o, d, z_prev, f_prev, z, f, c);
      vec3 qh = o + d * zh;
      vec3 col{0.f, 0.f, 0.f};
      float fh = 0.f;
      sample_tsdf(a, qh, c, &fh, &col);
      // The normal is the TSDF gradient (voxel and world axes are parallel, spacing isotropic).
      vec3 nw = normalize(tsdf_gradient(a, qh, fh, c));
      out.depth(x, y) = zh;
      out.vertex(x, y) = g.to_world(qh);
      out.normal(x, y) = nw;
      out.color(x, y) = {static_cast<std::uint8_t>(col.x + 0.5f), static_cast<std::uint8_t>(col.y + 0.5f),
                         static_cast<std::uint8_t>(col.z + 0.5f)};
      return;
    }
    z_prev = z, f_prev = f, have_prev = true;
    // The TSDF is at most about the distance to the surface (projective distances over-estimate
    // at grazing angles, hence the 0.8), so stepping that far along the ray (|d| s metres per unit
    // of z) cannot jump over a zero crossing.
    z += fmaxf(0.8f * f / (dlen * g.voxel_size), min_step);
  }
}

template <class Exec, class Acc>
void raycast(const Exec& ex, Acc a, Intrinsics K, SE3 world_T_camera, float min_depth, float max_depth,
             RaycastOutput out) {
  const int w = out.depth.width;
  ex.for_each(out.depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    raycast_pixel(a, static_cast<int>(i % w), static_cast<int>(i / w), K, world_T_camera, min_depth, max_depth, out);
  });
}

}  // namespace seamless::kernels

#define SEAMLESS_INSTANTIATE_TSDF_RAYCAST(EXEC)                                                                  \
  namespace seamless::kernels {                                                                                  \
  template void raycast<EXEC, HashAccess>(const EXEC&, HashAccess, Intrinsics, SE3, float, float, RaycastOutput); \
  template void raycast<EXEC, DenseAccess>(const EXEC&, DenseAccess, Intrinsics, SE3, float, float,              \
                                           RaycastOutput);                                                       \
  }
