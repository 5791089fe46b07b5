// Analytic test scenes for the TSDF tests: depth maps ray-traced exactly from planes and spheres,
// and the scene's signed distance, so that results can be checked against truth.
#pragma once
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "recon/volume_params.hpp"
#include "recon/voxel_hash_volume.hpp"

namespace seamless::test {

// A wall (solid half-space z >= wall_z) with a sphere in front of it, plus optionally a box
// standing on nothing (axis-aligned, solid), all in world coordinates.
struct Scene {
  float wall_z = 1.6f;
  bool sphere = true;
  vec3 center{0.05f, 0.f, 1.2f};
  float radius = 0.2f;
  bool box = false;
  vec3 box_lo{-0.2f, -0.1f, 1.0f}, box_hi{0.2f, 0.1f, 1.3f};

  // Exact signed distance outside the solids (positive in free space).
  float sdf(vec3 p) const {
    float d = wall_z - p.z;
    if (sphere) d = std::min(d, length(p - center) - radius);
    if (box) {
      vec3 c = (box_lo + box_hi) * 0.5f, h = (box_hi - box_lo) * 0.5f;
      vec3 q{std::fabs(p.x - c.x) - h.x, std::fabs(p.y - c.y) - h.y, std::fabs(p.z - c.z) - h.z};
      vec3 qo{std::max(q.x, 0.f), std::max(q.y, 0.f), std::max(q.z, 0.f)};
      d = std::min(d, length(qo) + std::min(std::max(q.x, std::max(q.y, q.z)), 0.f));
    }
    return d;
  }

  // Ray parameter t (>0) of the first hit of o + t d, or 0 for none; n gets the outward normal.
  float intersect(vec3 o, vec3 d, vec3* n) const {
    float best = 1e30f;
    if (d.z > 0.f) {
      float t = (wall_z - o.z) / d.z;
      if (t > 0.f && t < best) best = t, *n = {0.f, 0.f, -1.f};
    }
    if (sphere) {
      vec3 oc = o - center;
      float b = dot(oc, d), c = dot(oc, oc) - radius * radius, a = dot(d, d);
      float disc = b * b - a * c;
      if (disc >= 0.f) {
        float t = (-b - std::sqrt(disc)) / a;
        if (t > 0.f && t < best) best = t, *n = normalize(o + d * t - center);
      }
    }
    if (box) {
      float tmin = 0.f, tmax = 1e30f;
      float oo[3] = {o.x, o.y, o.z}, dd[3] = {d.x, d.y, d.z}, lo[3] = {box_lo.x, box_lo.y, box_lo.z},
            hi[3] = {box_hi.x, box_hi.y, box_hi.z};
      int axis = -1;
      float sgn = 0.f;
      for (int k = 0; k < 3; ++k) {
        if (std::fabs(dd[k]) < 1e-12f) {
          if (oo[k] < lo[k] || oo[k] > hi[k]) tmin = 1e30f;
          continue;
        }
        float t0 = (lo[k] - oo[k]) / dd[k], t1 = (hi[k] - oo[k]) / dd[k];
        float s = -1.f;
        if (t0 > t1) std::swap(t0, t1), s = 1.f;
        if (t0 > tmin) tmin = t0, axis = k, sgn = s;
        tmax = std::min(tmax, t1);
      }
      if (tmin <= tmax && tmin > 0.f && tmin < best && axis >= 0) {
        best = tmin;
        *n = {axis == 0 ? sgn : 0.f, axis == 1 ? sgn : 0.f, axis == 2 ? sgn : 0.f};
      }
    }
    return best < 1e29f ? best : 0.f;
  }

  // Camera-z depth (metres, 0 = nothing) as a pinhole camera at world_T_camera sees the scene.
  std::vector<float> render(const Intrinsics& K, const SE3& world_T_camera,
                            std::vector<vec3>* normals = nullptr) const {
    std::vector<float> depth(static_cast<std::size_t>(K.width) * K.height, 0.f);
    if (normals) normals->assign(depth.size(), vec3{0.f, 0.f, 0.f});
    for (int y = 0; y < K.height; ++y)
      for (int x = 0; x < K.width; ++x) {
        vec3 dc = K.unproject(float(x), float(y), 1.f);  // z = 1: t is the camera depth
        vec3 n{0.f, 0.f, 0.f};
        float t = intersect(world_T_camera.t, world_T_camera.rotate(dc), &n);
        depth[static_cast<std::size_t>(y) * K.width + x] = t;
        if (normals) (*normals)[static_cast<std::size_t>(y) * K.width + x] = n;
      }
    return depth;
  }
};

// A rotation about the y axis then x (radians), for small camera motions.
inline SE3 pose(vec3 t, float yaw = 0.f, float pitch = 0.f) {
  float cy = std::cos(yaw), sy = std::sin(yaw), cp = std::cos(pitch), sp = std::sin(pitch);
  mat3 Ry{{{cy, 0, sy}, {0, 1, 0}, {-sy, 0, cy}}};
  mat3 Rx{{{1, 0, 0}, {0, cp, -sp}, {0, sp, cp}}};
  return {Ry * Rx, t};
}

inline Intrinsics camera(int w, int h, float f) {
  Intrinsics K;
  K.width = w, K.height = h, K.fx = K.fy = f, K.cx = (w - 1) * 0.5f, K.cy = (h - 1) * 0.5f;
  return K;
}

// Colour that encodes where a point is, so that fused colour can be checked too.
inline uchar3 colour_of(vec3 n) {
  return {static_cast<std::uint8_t>(127.5f + 127.f * n.x), static_cast<std::uint8_t>(127.5f + 127.f * n.y),
          static_cast<std::uint8_t>(127.5f + 127.f * n.z)};
}

// A small volume for these scenes: 1 cm voxels, 3 cm truncation, room for the wall and sphere.
inline VolumeParams small_volume_params() {
  VolumeParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.03f;
  p.hash_buckets = 1 << 14;
  p.capacity = 4096;
  p.min_depth = 0.2f;
  p.max_depth = 3.f;
  return p;
}

// Two volumes' downloaded blocks (download_blocks(), sorted) hold the same blocks with the same
// weights and TSDF values within one snorm16 step (kernels::Voxel), and, with colour, the same
// colour within one level. The backends' float arithmetic differs by reassociation (ulps of the
// observation, a thousandth of a step), which can put the two averages on either side of a
// rounding boundary: one step apart. The next frame keeps them at most one apart: the two
// unrounded updates q + (t - q) / (w + 1) then differ by w / (w + 1) < 1 step (plus ulps), and
// rounding two values less than a step apart gives neighbouring steps at most. Call through
// ASSERT_NO_FATAL_FAILURE.
inline void expect_same_blocks(const std::vector<VoxelHashVolume::HostBlock>& a,
                               const std::vector<VoxelHashVolume::HostBlock>& b, bool colour) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_TRUE(a[i].coord == b[i].coord);
    for (int k = 0; k < kernels::kBlockVoxels; ++k) {
      ASSERT_EQ(a[i].voxels[k].weight16, b[i].voxels[k].weight16);
      ASSERT_LE(std::abs(int(a[i].voxels[k].sdf16) - int(b[i].voxels[k].sdf16)), 1);
      if (colour) {
        ASSERT_NEAR(a[i].colors[k].x, b[i].colors[k].x, 1);
        ASSERT_NEAR(a[i].colors[k].y, b[i].colors[k].y, 1);
        ASSERT_NEAR(a[i].colors[k].z, b[i].colors[k].z, 1);
      }
    }
  }
}

}  // namespace seamless::test
