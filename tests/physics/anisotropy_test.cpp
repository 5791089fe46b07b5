// The fluid's anisotropic kernels (kernels/physics/anisotropy.hpp, physics/fluid_ellipsoids.hpp):
// the ellipsoids of lattices whose shape follows from symmetry (a flat layer, a tilted one, a bulk
// block, a lone drop), and of a random cloud against an independent double-precision reference
// (brute-force neighbours, Eigen's symmetric eigensolver); CPU and CUDA agree (gpu label).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include "core/device.hpp"
#include "core/error.hpp"
#include "core/phase.hpp"
#include "kernels/physics/anisotropy.hpp"
#include "physics/fluid_ellipsoids.hpp"

namespace seamless {
namespace {
// Named: the unity build compiles this file with others whose helpers are in anonymous namespaces.
namespace ellipsoids_test {

constexpr float kR = 0.01f;     // sphere radius drawn
constexpr float kD = 2.f * kR;  // lattice spacing: one particle diameter
constexpr float kH = 3.f * kD;  // neighbourhood: three spacings (the renderer's is two, kNeighbourhoodRadii)
constexpr int kV = kernels::kEllipsoidVec4s;

struct Ellipsoid {
  Eigen::Vector3d centre;
  double bound = 0.0;
  Eigen::Matrix3d M;
  bool lone = false;    // a fluid particle with fewer than kMinNeighbours fluid neighbours
  double offset = 1.0;  // the neighbours' weighted mean from the particle, in h (1: lone or not fluid)
};

Ellipsoid ellipsoid(const std::vector<vec4>& e, std::size_t i) {
  const vec4 a = e[kV * i], b = e[kV * i + 1], c = e[kV * i + 2];
  Ellipsoid out;
  out.centre = {a.x, a.y, a.z};
  out.bound = a.w;
  out.M << b.x, b.y, b.z, b.y, b.w, c.x, b.z, c.x, c.y;
  out.lone = c.z == 1.f;
  out.offset = c.w;
  EXPECT_TRUE(c.z == 0.f || c.z == 1.f) << "the lone flag of particle " << i;
  return out;
}

std::vector<vec4> shapes(const std::vector<vec3>& x, const std::vector<std::uint32_t>& ph, Device d = Device::CPU) {
  return FluidEllipsoids(d).compute_host(x, ph, kR, kH);
}

std::vector<std::uint32_t> fluid(std::size_t n) { return std::vector<std::uint32_t>(n, phase::kFluid); }

// A square lattice of (2k + 1)^2 particles in the plane through `o` spanned by u and v; the centre
// particle is index 0.
std::vector<vec3> layer(vec3 o, vec3 u, vec3 v, int k) {
  std::vector<vec3> x{o};
  for (int i = -k; i <= k; ++i)
    for (int j = -k; j <= k; ++j)
      if (i != 0 || j != 0) x.push_back(o + (kD * static_cast<float>(i)) * u + (kD * static_cast<float>(j)) * v);
  return x;
}

// A flat layer's ellipsoid: in-plane covariance isotropic (the square lattice's 4-fold symmetry),
// none across, so the normal axis is clamped to a quarter of the in-plane ones and the axes keep
// the sphere's volume: in-plane r 4^(1/3), normal r 4^(1/3) / 4.
Eigen::Matrix3d flat_layer_M(const Eigen::Vector3d& normal) {
  const double a = kR * std::cbrt(4.0), c = a / kernels::kMaxAxisRatio;
  const Eigen::Matrix3d P = normal * normal.transpose();
  return (Eigen::Matrix3d::Identity() - P) / (a * a) + P / (c * c);
}

// Float sums over ~30 neighbours and a float eigensolver: relative errors of ~1e-6; 1e-4 of the
// matrix's norm is far below any shape change (a 4:1 axis ratio is a factor 16 in M).
void expect_near_M(const Eigen::Matrix3d& got, const Eigen::Matrix3d& want) {
  EXPECT_LT((got - want).norm(), 1e-4 * want.norm()) << "got\n" << got << "\nwant\n" << want;
}

TEST(FluidEllipsoids, AFlatLayerBecomesADiscOfTheSphereVolume) {
  const std::vector<vec3> x = layer({0.3f, 0.1f, -0.2f}, {1, 0, 0}, {0, 0, 1}, 6);
  const Ellipsoid e = ellipsoid(shapes(x, fluid(x.size())), 0);
  expect_near_M(e.M, flat_layer_M({0, 1, 0}));
  EXPECT_NEAR(e.bound, kR * std::cbrt(4.0), 1e-4 * kR);
  EXPECT_NEAR((e.centre - Eigen::Vector3d(0.3, 0.1, -0.2)).norm(), 0.0, 1e-6);  // mean offset 0 by symmetry
}

TEST(FluidEllipsoids, ATiltedLayerTurnsItsDiscWithIt) {
  const vec3 u = normalize(vec3{1.f, 0.5f, 0.f}), w = normalize(cross(u, vec3{0.2f, 0.3f, 1.f}));
  const vec3 v = cross(w, u);  // u, v span the plane, w its normal
  const std::vector<vec3> x = layer({0.f, 0.f, 0.f}, u, v, 6);
  const Ellipsoid e = ellipsoid(shapes(x, fluid(x.size())), 0);
  expect_near_M(e.M, flat_layer_M(Eigen::Vector3d(w.x, w.y, w.z)));
}

TEST(FluidEllipsoids, BulkFluidAndALoneDropStaySpheres) {
  std::vector<vec3> x{{0.f, 0.f, 0.f}};
  for (int i = -4; i <= 4; ++i)
    for (int j = -4; j <= 4; ++j)
      for (int k = -4; k <= 4; ++k)
        if (i || j || k) x.push_back(kD * vec3{float(i), float(j), float(k)});
  x.push_back({1.f, 1.f, 1.f});  // a lone drop far away
  const std::vector<vec4> e = shapes(x, fluid(x.size()));
  // The cubic lattice's covariance is isotropic: the sphere, at the particle.
  const Ellipsoid bulk = ellipsoid(e, 0), lone = ellipsoid(e, x.size() - 1);
  expect_near_M(bulk.M, Eigen::Matrix3d::Identity() / (kR * kR));
  EXPECT_NEAR(bulk.bound, kR, 1e-4 * kR);
  EXPECT_NEAR(bulk.centre.norm(), 0.0, 1e-6);
  EXPECT_EQ(lone.M, Eigen::Matrix3d::Identity() * double(1.f / (kR * kR)));
  EXPECT_TRUE(lone.lone);
  EXPECT_FALSE(bulk.lone);
  EXPECT_EQ(lone.bound, double(kR));
  EXPECT_EQ(lone.centre, Eigen::Vector3d(1.0, 1.0, 1.0));
  // The neighbours' weighted mean: at the particle inside (symmetry), a fifth of h or more
  // towards the inside at a face (a half space's neighbourhood: 0.23 h for h = 3 spacings), 1
  // for the drop.
  EXPECT_NEAR(bulk.offset, 0.0, 1e-6);
  EXPECT_EQ(lone.offset, 1.0);
  const vec3 f = kD * vec3{4.f, 0.f, 0.f};
  const auto face = static_cast<std::size_t>(
      std::find_if(x.begin(), x.end(), [&](vec3 p) { return p.x == f.x && p.y == f.y && p.z == f.z; }) - x.begin());
  ASSERT_LT(face, x.size());
  EXPECT_NEAR(ellipsoid(e, face).offset, 0.2305, 1e-3);
}

TEST(FluidEllipsoids, OnlyFluidNeighboursShapeAFluidParticle) {
  // A fluid particle lying in a layer of rigid particles: no fluid neighbour, so the sphere; the
  // rigid particles get the sphere too.
  const std::vector<vec3> x = layer({0.f, 0.f, 0.f}, {1, 0, 0}, {0, 0, 1}, 4);
  std::vector<std::uint32_t> ph(x.size(), phase::kRigid);
  ph[0] = phase::kFluid;
  const std::vector<vec4> e = shapes(x, ph);
  for (std::size_t i : {std::size_t{0}, std::size_t{1}, x.size() - 1}) {
    const Ellipsoid s = ellipsoid(e, i);
    expect_near_M(s.M, Eigen::Matrix3d::Identity() / (kR * kR));
    EXPECT_EQ(s.centre, Eigen::Vector3d(x[i].x, x[i].y, x[i].z));
    EXPECT_EQ(s.lone, i == 0) << "only the fluid particle is a lone drop";
  }
}

TEST(FluidEllipsoids, PhasesOfTheWrongCountAreAnError) {
  const std::vector<vec3> x(3, vec3{0.f, 0.f, 0.f});
  EXPECT_THROW(FluidEllipsoids(Device::CPU).compute_host(x, fluid(2), kR, kH), Error);
  EXPECT_THROW(FluidEllipsoids(Device::CPU).compute_host(x, fluid(3), 0.f, kH), Error);  // no size
}

// The reference: every pair by brute force in double precision, Eigen's eigensolver, the same
// rules (weights 1 - (d / h)^3, at least kMinNeighbours, axes clamped and scaled, centre
// smoothing) written out independently of the kernel.
Ellipsoid reference(const std::vector<vec3>& x, const std::vector<std::uint32_t>& ph, std::size_t i) {
  const Eigen::Vector3d xi(x[i].x, x[i].y, x[i].z);
  Ellipsoid out{xi, kR, Eigen::Matrix3d::Identity() / (double(kR) * kR), false};
  if (!phase::is(ph[i], phase::kFluid)) return out;
  double sw = 0.0;
  Eigen::Vector3d sy = Eigen::Vector3d::Zero();
  Eigen::Matrix3d syy = Eigen::Matrix3d::Zero();
  int neighbours = 0;
  for (std::size_t j = 0; j < x.size(); ++j) {
    if (!phase::is(ph[j], phase::kFluid)) continue;
    const Eigen::Vector3d y = Eigen::Vector3d(x[j].x, x[j].y, x[j].z) - xi;
    const double q = y.norm() / kH;
    if (q >= 1.0) continue;
    const double w = 1.0 - q * q * q;
    sw += w, sy += w * y, syy += w * y * y.transpose();
    neighbours += j != i;
  }
  out.lone = neighbours < kernels::kMinNeighbours;
  if (out.lone) return out;
  const Eigen::Vector3d mean = sy / sw;
  out.offset = mean.norm() / kH;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(syy / sw - mean * mean.transpose());
  Eigen::Vector3d sd = es.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  sd = sd.cwiseMax(sd.maxCoeff() / kernels::kMaxAxisRatio);
  const Eigen::Vector3d axes = kR * sd / std::cbrt(sd.prod());
  out.M = es.eigenvectors() * axes.cwiseInverse().cwiseAbs2().asDiagonal() * es.eigenvectors().transpose();
  out.bound = axes.maxCoeff();
  out.centre = xi + kernels::kCentreSmoothing * mean;
  return out;
}

// A cloud of fluid drops and a few solid particles: a thin slab (flat neighbourhoods), a denser
// core (round ones) and stragglers (spheres).
void random_cloud(int n, std::uint32_t seed, std::vector<vec3>& x, std::vector<std::uint32_t>& ph) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-0.15f, 0.15f), t(-0.006f, 0.006f), c(-0.04f, 0.04f), f(0.f, 1.f);
  for (int i = 0; i < n; ++i) {
    const float r = f(rng);
    x.push_back(r < 0.6f   ? vec3{u(rng), t(rng), u(rng)}
                : r < 0.9f ? vec3{c(rng), c(rng), c(rng)}
                           : 3.f * vec3{u(rng), u(rng), u(rng)});
    ph.push_back(f(rng) < 0.1f ? phase::kRigid : phase::kFluid);
  }
}

TEST(FluidEllipsoids, ARandomCloudMatchesADoublePrecisionReference) {
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  random_cloud(1500, 7, x, ph);
  const std::vector<vec4> e = shapes(x, ph);
  int shaped = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Ellipsoid got = ellipsoid(e, i), want = reference(x, ph, i);
    shaped += want.bound > 1.001 * kR;
    ASSERT_LT((got.M - want.M).norm(), 1e-3 * want.M.norm()) << "particle " << i;
    ASSERT_NEAR((got.centre - want.centre).norm(), 0.0, 1e-6) << "particle " << i;
    ASSERT_NEAR(got.bound, want.bound, 1e-3 * want.bound) << "particle " << i;
    ASSERT_EQ(got.lone, want.lone) << "particle " << i;
    ASSERT_NEAR(got.offset, want.offset, 1e-4) << "particle " << i;
  }
  EXPECT_GT(shaped, 500);  // the slab's particles are discs, so the comparison covers shapes
}

TEST(FluidEllipsoidsParity, CpuAndCudaAgree) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device";
  std::vector<vec3> x;
  std::vector<std::uint32_t> ph;
  random_cloud(20000, 11, x, ph);
  const std::vector<vec4> a = shapes(x, ph, Device::CPU), b = shapes(x, ph, Device::CUDA);
  ASSERT_EQ(a.size(), b.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const Ellipsoid p = ellipsoid(a, i), q = ellipsoid(b, i);
    worst = std::max(worst, (p.M - q.M).norm() / p.M.norm());
    ASSERT_EQ(p.lone, q.lone) << "particle " << i;
    ASSERT_NEAR((p.centre - q.centre).norm(), 0.0, 1e-6) << "particle " << i;
  }
  std::printf("ellipsoid parity: largest relative CPU/CUDA difference of M %.3g\n", worst);
  EXPECT_LT(worst, 1e-4);  // the same sums in the same order; FMA contraction only
}

}  // namespace ellipsoids_test
}  // namespace
}  // namespace seamless
