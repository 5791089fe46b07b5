// Preprocessing kernels against analytic geometry, on the CPU, and CPU/CUDA parity.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "kernels/recon/preprocess.hpp"

using namespace seamless;

namespace {

const Intrinsics kK{517.3f, 516.5f, 318.6f, 255.3f, 640, 480, {0, 0, 0, 0, 0}};

vec3 ray(const Intrinsics& K, int x, int y) { return {(x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.f}; }

// Depth (z) of the plane dot(n, p) = d seen through every pixel; n points towards the camera.
std::vector<float> plane_depth(const Intrinsics& K, vec3 n, float d) {
  std::vector<float> z(K.width * K.height);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) z[y * K.width + x] = d / dot(n, ray(K, x, y));
  return z;
}

// Depth of a sphere (centre c, radius r) on a far wall at z = wall; 0 nowhere.
std::vector<float> sphere_depth(const Intrinsics& K, vec3 c, float r, float wall) {
  std::vector<float> z(K.width * K.height);
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      vec3 dir = ray(K, x, y);
      float a = dot(dir, dir), b = -2.f * dot(dir, c), cc = dot(c, c) - r * r;
      float disc = b * b - 4 * a * cc;
      z[y * K.width + x] = disc >= 0 ? (-b - std::sqrt(disc)) / (2 * a) : wall;
    }
  return z;
}

struct Maps {
  std::vector<vec3> vertices, normals;
};

Maps vertex_normal_maps(Device dev, const std::vector<float>& depth, const Intrinsics& K, float max_edge) {
  auto d = Image<float>::from_host(depth, K.width, K.height, dev);
  Image<vec3> v(K.width, K.height, dev), n(K.width, K.height, dev);
  with_exec(dev, [&]<class E>(const E& ex) {
    kernels::Preprocess<E>::depth_to_vertices(ex, d.cview(), K, v.view());
    kernels::Preprocess<E>::vertices_to_normals(ex, v.cview(), n.view(), max_edge);
  });
  return {v.to_host(), n.to_host()};
}

TEST(Preprocess, PlaneNormalsAreExact) {
  const vec3 n = normalize(vec3{0.3f, -0.5f, -1.f});  // faces the camera (negative z)
  const float d = -1.5f;                              // dot(n, p) = d with p.z > 0
  auto depth = plane_depth(kK, n, d);
  auto m = vertex_normal_maps(Device::CPU, depth, kK, 0.1f);
  // Forward differences on a plane span the plane exactly; the only error is float rounding of
  // vertices of magnitude ~2 m over edges of ~4 mm: 2 m * 6e-8 / 4 mm ~ 3e-5 rad. 1e-3 rad is safe.
  int valid = 0;
  for (int y = 0; y + 1 < kK.height; ++y)
    for (int x = 0; x + 1 < kK.width; ++x) {
      vec3 got = m.normals[y * kK.width + x];
      ASSERT_GT(length(got), 0.5f) << x << "," << y;
      EXPECT_GT(dot(got, n), std::cos(1e-3f)) << x << "," << y;
      ++valid;
      vec3 p = m.vertices[y * kK.width + x];
      EXPECT_NEAR(dot(n, p), d, 1e-5f);
    }
  EXPECT_EQ(valid, (kK.width - 1) * (kK.height - 1));
}

TEST(Preprocess, SphereNormalsMatchAnalytic) {
  const vec3 c{0.1f, -0.05f, 1.2f};
  const float r = 0.3f, wall = 3.f;
  auto m = vertex_normal_maps(Device::CPU, sphere_depth(kK, c, r, wall), kK, 0.05f);
  int checked = 0;
  for (int y = 0; y + 1 < kK.height; ++y)
    for (int x = 0; x + 1 < kK.width; ++x) {
      vec3 p = m.vertices[y * kK.width + x], got = m.normals[y * kK.width + x];
      if (std::fabs(length(p - c) - r) > 1e-3f) continue;  // wall or silhouette pixel
      vec3 truth = normalize(p - c);
      if (-dot(truth, normalize(p)) < 0.5f) continue;  // grazing: pixel footprint > 2x
      if (length(got) == 0.f) continue;                // a neighbour fell on the wall
      // The forward-difference normal is that of the chord plane through p and its two
      // neighbours. At 1.2 m a pixel spans ~2.3 mm, up to ~4.6 mm at 60 degrees incidence; on a
      // sphere of radius 0.3 m the chord normal tilts by at most about edge / r = 0.016 rad.
      // We allow 0.03 rad.
      EXPECT_GT(dot(got, truth), std::cos(0.03f)) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, 20000);  // the sphere covers ~ pi (0.3 * 517 / 1.2)^2 ~ 55k pixels
}

TEST(Preprocess, DepthJumpGivesNoNormal) {
  auto depth = plane_depth(kK, {0, 0, -1}, -1.f);
  for (int y = 0; y < kK.height; ++y)
    for (int x = 320; x < kK.width; ++x) depth[y * kK.width + x] = 2.f;
  auto m = vertex_normal_maps(Device::CPU, depth, kK, 0.1f);
  EXPECT_EQ(length(m.normals[100 * kK.width + 319]), 0.f);  // straddles the 1 m jump
  EXPECT_GT(length(m.normals[100 * kK.width + 318]), 0.5f);
}

TEST(Preprocess, BilateralKeepsPlanesAndEdges) {
  // A fronto-parallel plane is a fixed point (weights are normalised); a 0.5 m step stays a step
  // because exp(-0.5^2 / (2 * 0.03^2)) ~ 1e-30 removes the far side's weight.
  auto depth = plane_depth(kK, {0, 0, -1}, -1.f);
  for (int y = 0; y < kK.height; ++y)
    for (int x = 320; x < kK.width; ++x) depth[y * kK.width + x] = 1.5f;
  depth[10 * kK.width + 10] = 0.f;  // a hole stays a hole
  auto in = Image<float>::from_host(depth, kK.width, kK.height, Device::CPU);
  Image<float> out(kK.width, kK.height, Device::CPU);
  kernels::Preprocess<CpuExec>::bilateral_filter(CpuExec{}, in.cview(), out.view(), 4.5f, 0.03f, 3);
  auto r = out.to_host();
  for (std::size_t i = 0; i < r.size(); ++i) ASSERT_NEAR(r[i], depth[i], 1e-6f) << i;
}

TEST(ExpNonpositive, RelativeErrorBound) {
  // The bound its comment derives: truncation ~5e-9, the reduction's rounding ~0.7 ulp of e^r, the
  // Horner steps' ~2 ulp (u = 6e-8 each); 3e-7 is ~2.5 ulp. Every 97th float of [-87, 0].
  const std::uint32_t last = std::bit_cast<std::uint32_t>(87.f);
  double worst = 0.0;
  for (std::uint32_t m = 0; m <= last; m += 97) {
    const float x = -std::bit_cast<float>(m);
    const double truth = std::exp(static_cast<double>(x));
    worst = std::max(worst, std::fabs(kernels::exp_nonpositive(x) - truth) / truth);
  }
  EXPECT_LT(worst, 3e-7);
  EXPECT_EQ(kernels::exp_nonpositive(0.f), 1.f);  // a pixel's own tap weighs exactly 1
  EXPECT_EQ(kernels::exp_nonpositive(-87.5f), 0.f);
  EXPECT_EQ(kernels::exp_nonpositive(std::nanf("")), 0.f);
}

// The bilateral filter on dev against KinectFusion eq. 2 evaluated in double, pixel by pixel, with
// a first-order bound of the float filter's error (u = 2^-24):
// - a weight w = e^x is off by w (8 u |x| + 3e-7): the float argument's ~6 roundings (8 allowed)
//   and the exp's own error: exp_nonpositive's (ExpNonpositive.RelativeErrorBound), or expf's
//   (glibc: < 1 ulp; CUDA: 2 ulp, CUDA C Programming Guide, "Mathematical Functions"), or by w
//   itself where x is near -87 and the float weight may be 0 (exp_nonpositive flushes below -87);
//   it moves the result by sum |dw_k| |d_k - out| / W;
// - the sums S = sum w d and W = sum w, in tap order, are off by u (sum of w_k d_k + the partial
//   sums S_i after the first) and u (the partial sums W_i after the first) (Higham, "Accuracy and
//   Stability of Numerical Algorithms", eq. 4.4), which moves S / W by err_S / W + out err_W / W;
//   the division adds u out. 5 % more covers the second-order terms.
void expect_bilateral_matches_exact_formula(Device dev, bool inline_exp) {
  const float sigma_s = 4.5f, sigma_d = 0.03f;
  const int r = 3, W = 160, H = 120;
  // A noisy slanted surface (weights across their whole range), random far readings (weights that
  // underflow), holes, and a step; the image is small, so the border is a large part of it.
  std::mt19937 rng(11);
  std::normal_distribution<float> noise(0.f, 0.02f);
  std::uniform_real_distribution<float> far(0.5f, 4.f);
  std::vector<float> depth(W * H);
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const int i = y * W + x;
      depth[i] = (x < 100 ? 1.f + 0.002f * x : 1.8f) + noise(rng);
      if (i % 13 == 0) depth[i] = far(rng);
      if (i % 31 == 0) depth[i] = 0.f;
    }
  auto in = Image<float>::from_host(depth, W, H, dev);
  Image<float> out(W, H, dev);
  with_exec(dev, [&]<class E>(const E& ex) {
    kernels::Preprocess<E>::bilateral_filter(ex, in.cview(), out.view(), sigma_s, sigma_d, r, inline_exp);
  });
  const auto got = out.to_host();
  const double u = std::ldexp(1.0, -24);
  const double inv_s2 = 0.5 / (double(sigma_s) * sigma_s), inv_d2 = 0.5 / (double(sigma_d) * sigma_d);
  int checked = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      const double d0 = depth[y * W + x];
      if (!(d0 > 0.0)) {
        ASSERT_EQ(got[y * W + x], 0.f) << x << "," << y;
        continue;
      }
      std::vector<double> w, d;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if (xx < 0 || yy < 0 || xx >= W || yy >= H || !(depth[yy * W + xx] > 0.f)) continue;
          d.push_back(depth[yy * W + xx]);
          w.push_back(std::exp(-(dx * dx + dy * dy) * inv_s2 - (d.back() - d0) * (d.back() - d0) * inv_d2));
        }
      double S = 0, Wt = 0, sum_wd = 0, partial_S = 0, partial_W = 0;
      for (std::size_t k = 0; k < w.size(); ++k) {
        S += w[k] * d[k];
        Wt += w[k];
        sum_wd += w[k] * d[k];
        if (k > 0) partial_S += S, partial_W += Wt;
      }
      const double exact = S / Wt;
      double weight_err = 0;
      for (std::size_t k = 0; k < w.size(); ++k) {
        const double x_k = std::log(w[k]);
        const double dw = x_k < -86.0 ? w[k] : w[k] * (8 * u * std::fabs(x_k) + 3e-7);
        weight_err += dw * std::fabs(d[k] - exact);
      }
      const double bound =
          1.05 * (weight_err / Wt + u * (sum_wd + partial_S) / Wt + exact * u * partial_W / Wt + exact * u);
      ASSERT_NEAR(got[y * W + x], exact, bound) << x << "," << y;
      ++checked;
    }
  EXPECT_GT(checked, W * H * 9 / 10);
}

TEST(PreprocessBilateral, MatchesExactFormula) {
  expect_bilateral_matches_exact_formula(Device::CPU, false);
  expect_bilateral_matches_exact_formula(Device::CPU, true);
}

TEST(PreprocessParity, BilateralMatchesExactFormulaOnCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  expect_bilateral_matches_exact_formula(Device::CUDA, false);
  expect_bilateral_matches_exact_formula(Device::CUDA, true);
}

TEST(Preprocess, PyramidAveragesWithoutBridgingEdges) {
  // 4x2 -> 2x1: left block {1.0, 1.02, 1.04, hole}, right block {3.0, 3.0, 3.0, 3.1}.
  std::vector<float> d = {1.0f,  1.02f, 3.0f, 3.0f,  //
                          1.04f, 0.0f,  3.0f, 3.1f};
  auto in = Image<float>::from_host(d, 4, 2, Device::CPU);
  Image<float> out(2, 1, Device::CPU);
  kernels::Preprocess<CpuExec>::pyr_down_depth(CpuExec{}, in.cview(), out.view(), 0.1f);
  auto r = out.to_host();
  EXPECT_NEAR(r[0], (1.0f + 1.02f + 1.04f) / 3, 1e-6f);  // the hole is ignored
  EXPECT_NEAR(r[1], (3.0f + 3.0f + 3.0f + 3.1f) / 4, 1e-6f);
  std::vector<float> far = {1.0f, 2.0f, 2.0f, 2.0f};  // first valid depth is the reference
  auto in2 = Image<float>::from_host(far, 2, 2, Device::CPU);
  Image<float> out2(1, 1, Device::CPU);
  kernels::Preprocess<CpuExec>::pyr_down_depth(CpuExec{}, in2.cview(), out2.view(), 0.1f);
  EXPECT_FLOAT_EQ(out2.to_host()[0], 1.0f);
}

// Every preprocessing kernel on CPU and CUDA over the same noisy depth. Both backends evaluate the
// same expressions; they differ only by fused multiply-adds and CUDA's expf (2 ulp), so relative
// differences stay ~1e-6. 1e-5 (relative to ~1 m) leaves room for that.
TEST(PreprocessParity, CpuMatchesCuda) {
  if (!cuda_available()) GTEST_SKIP() << "no CUDA device on this machine";
  auto depth = sphere_depth(kK, {0.1f, -0.05f, 1.2f}, 0.3f, 3.f);
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.f, 0.003f);
  for (std::size_t i = 0; i < depth.size(); ++i) depth[i] = (i % 97 == 0) ? 0.f : depth[i] + noise(rng);
  auto run = [&](Device dev) {
    auto d = Image<float>::from_host(depth, 640, 480, dev);
    Image<float> f(640, 480, dev), half(320, 240, dev), ihalf(320, 240, dev);
    Image<vec3> v(640, 480, dev), n(640, 480, dev);
    with_exec(dev, [&]<class E>(const E& ex) {
      kernels::Preprocess<E>::bilateral_filter(ex, d.cview(), f.view(), 4.5f, 0.03f, 3);
      kernels::Preprocess<E>::pyr_down_depth(ex, f.cview(), half.view(), 0.09f);
      kernels::Preprocess<E>::pyr_down_intensity(ex, d.cview(), ihalf.view());
      kernels::Preprocess<E>::depth_to_vertices(ex, f.cview(), kK, v.view());
      kernels::Preprocess<E>::vertices_to_normals(ex, v.cview(), n.view(), 0.1f);
    });
    return std::make_tuple(f.to_host(), half.to_host(), ihalf.to_host(), v.to_host(), n.to_host());
  };
  auto [f0, h0, i0, v0, n0] = run(Device::CPU);
  auto [f1, h1, i1, v1, n1] = run(Device::CUDA);
  for (std::size_t i = 0; i < f0.size(); ++i) ASSERT_NEAR(f0[i], f1[i], 1e-5f) << i;
  for (std::size_t i = 0; i < h0.size(); ++i) ASSERT_NEAR(h0[i], h1[i], 1e-5f) << i;
  for (std::size_t i = 0; i < i0.size(); ++i) ASSERT_NEAR(i0[i], i1[i], 1e-5f) << i;
  for (std::size_t i = 0; i < v0.size(); ++i) ASSERT_LT(length(v0[i] - v1[i]), 1e-5f) << i;
  // Normals amplify vertex differences by 1/edge (~1/2 mm): compare directions where both exist.
  int differ = 0;
  for (std::size_t i = 0; i < n0.size(); ++i) {
    bool a = length(n0[i]) > 0, b = length(n1[i]) > 0;
    if (a != b) {
      ++differ;  // an edge test landing on the other side of max_edge by rounding
    } else if (a) {
      ASSERT_GT(dot(n0[i], n1[i]), 0.9999f) << i;
    }
  }
  EXPECT_LT(differ, 10);
}

}  // namespace
