// Scene particles and the SDF sampler against an analytic scene (a box in front of a wall).
#include <gtest/gtest.h>

#include <cmath>

#include "kernels/recon/voxel_hash.hpp"
#include "recon/voxel_hash_volume.hpp"
#include "tsdf_scene.hpp"

namespace seamless {
namespace {

using test::Scene;

Scene box_scene() {
  Scene s;
  s.sphere = false;
  s.box = true;
  return s;
}

VoxelHashVolume fused(const Scene& s, Device d = Device::CPU) {
  VolumeParams p;
  p.voxel_size = 0.01f;
  p.truncation = 0.04f;
  p.hash_buckets = 1 << 14;
  p.capacity = 4096;
  p.min_depth = 0.2f;
  VoxelHashVolume vol(p, d);
  Intrinsics K = test::camera(320, 240, 280.f);
  // Translations only: the projective distance to the fronto-parallel faces is then exact.
  for (SE3 T : {test::pose({0.f, 0.f, 0.f}), test::pose({0.05f, 0.f, 0.f}), test::pose({-0.05f, 0.03f, 0.f}),
                test::pose({0.f, -0.04f, 0.05f})})
    vol.integrate(Image<float>::from_host(s.render(K, T), K.width, K.height, d), Image<uchar3>{}, K, T);
  return vol;
}

TEST(TsdfParticles, LieOnTheSurfaceWithinHalfASpacing) {
  Scene s = box_scene();
  VoxelHashVolume vol = fused(s);
  SceneParticleParams pp;
  pp.spacing = 0.02f;
  SceneParticles sp = vol.extract_scene_particles(pp);
  ASSERT_GT(sp.count, 0);
  auto pos = sp.positions.to_host(), nrm = sp.normals.to_host();
  int front = 0;
  for (std::int64_t i = 0; i < sp.count; ++i) {
    vec3 p = pos[i];
    // Selection is |TSDF| <= s/2. The TSDF equals the true distance in front of the box's and the
    // wall's faces (fronto-parallel, seen head-on by translated cameras); beside the box's
    // edges it is the projective distance, which is never smaller than the true one in front of a
    // surface, so selection only gets stricter there. Float rounding: 1e-5.
    EXPECT_LE(std::fabs(s.sdf(p)), 0.5f * pp.spacing + 1e-5f) << p.x << " " << p.y << " " << p.z;
    EXPECT_NEAR(length(nrm[i]), 1.f, 1e-4f);
    // Particles on the lattice spacing * Z^3.
    EXPECT_NEAR(p.x / pp.spacing, std::round(p.x / pp.spacing), 1e-3f);
    if (std::fabs(p.z - s.box_lo.z) < 0.011f && std::fabs(p.x) < 0.17f && std::fabs(p.y) < 0.07f) {
      ++front;
      EXPECT_GT(-nrm[i].z, 0.99f);  // the front face looks at the camera
    }
  }
  // The box front (0.4 x 0.2 m) holds one lattice layer within s/2 of z = 1.0 (the lattice
  // planes z = 0.98 and 1.02 are a full spacing away): the part of it counted above has
  // x in {-0.16, ..., 0.16} and y in {-0.06, ..., 0.06}: 17 * 7 points, none missing.
  EXPECT_EQ(front, 17 * 7);
}

TEST(TsdfParticles, InteriorFillReachesTheRequestedDepth) {
  Scene s = box_scene();
  VoxelHashVolume vol = fused(s);
  SceneParticleParams pp;
  pp.spacing = 0.01f;
  pp.interior_depth = 0.03f;
  SceneParticles sp = vol.extract_scene_particles(pp);
  auto pos = sp.positions.to_host();
  float deepest = 0.f;
  for (vec3 p : pos) {
    EXPECT_GE(s.sdf(p), -pp.interior_depth - 1e-5f);
    EXPECT_LE(s.sdf(p), 0.5f * pp.spacing + 1e-5f);
    deepest = std::min(deepest, s.sdf(p));
  }
  EXPECT_LT(deepest, -0.025f);  // the lattice reaches within one spacing of the requested depth
}

TEST(TsdfSampler, ValueAndGradientMatchTheWall) {
  Scene s = box_scene();
  VoxelHashVolume vol = fused(s);
  kernels::HashAccess view = vol.device_view();  // CPU memory: callable from host code here
  int checked = 0;
  for (float x = -0.7f; x <= 0.7f; x += 0.0737f)
    for (float z = 1.565f; z <= 1.63f; z += 0.0071f) {
      vec3 p{x, 0.35f, z};  // above the box, away from its edges
      float v;
      vec3 g;
      if (!kernels::sample_sdf(view, p, &v, &g)) continue;
      ++checked;
      // Trilinear interpolation of a linear field is exact; float rounding 1e-5.
      EXPECT_NEAR(v, std::min(s.wall_z - p.z, 0.04f), 1e-5f);
      if (std::fabs(s.wall_z - p.z) < 0.025f) {  // gradient stencil (+-1 voxel) inside the band
        EXPECT_NEAR(g.z, -1.f, 1e-3f);
        EXPECT_NEAR(g.x, 0.f, 1e-3f);
      }
    }
  EXPECT_GT(checked, 100);
  float v;
  EXPECT_FALSE(kernels::sample_sdf(view, vec3{0.f, 0.f, 0.5f}, &v, nullptr));  // free space: unknown
}

TEST(TsdfSampler, GridSamplesMatchTheWallAndFillUnknown) {
  // The grid is sample_sdf at grid points: the same exactness as above near the wall, and the
  // truncation distance (free space) where nothing was observed.
  Scene s = box_scene();
  VoxelHashVolume vol = fused(s);
  const vec3 origin{-0.5f, 0.35f, 1.40f};
  const int3 dims{21, 1, 31};
  const float voxel = 0.01f;
  std::vector<float> g = vol.sample_sdf_grid(origin, dims, voxel);
  ASSERT_EQ(g.size(), 21u * 31u);
  int near_wall = 0;
  for (int z = 0; z < dims.z; ++z)
    for (int x = 0; x < dims.x; ++x) {
      vec3 p = origin + vec3{float(x), 0.f, float(z)} * voxel;
      float v = g[z * dims.x + x];
      EXPECT_LE(v, 0.04f + 1e-6f);  // never beyond the truncation
      if (std::fabs(s.wall_z - p.z) < 0.03f) {
        EXPECT_NEAR(v, s.wall_z - p.z, 1e-4f) << p.x << " " << p.z;
        ++near_wall;
      }
    }
  EXPECT_GT(near_wall, 100);
  EXPECT_FLOAT_EQ(vol.sample_sdf_grid({0.f, 0.f, 0.5f}, {1, 1, 1}, 0.01f)[0], 0.04f);  // unobserved: free space
}

// The grid on both backends from volumes fused on each: the fused values agree to float rounding
// (TsdfParity), and trilinear sampling adds a few ulps; 1e-5 m is far below a voxel.
TEST(TsdfSamplerParity, GridOnCpuAndCudaAgree) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  Scene s = box_scene();
  VoxelHashVolume a = fused(s, Device::CPU), b = fused(s, Device::CUDA);
  const vec3 origin{-0.5f, -0.3f, 0.9f};
  const int3 dims{50, 30, 40};
  std::vector<float> ga = a.sample_sdf_grid(origin, dims, 0.02f), gb = b.sample_sdf_grid(origin, dims, 0.02f);
  ASSERT_EQ(ga.size(), gb.size());
  for (std::size_t i = 0; i < ga.size(); ++i) ASSERT_NEAR(ga[i], gb[i], 1e-5f) << i;
}

}  // namespace
}  // namespace seamless
