// Preprocessing of one 640x480 depth frame: what every tracked frame pays before ICP.
#include <cmath>
#include <memory>

#include "app/bench_cases.hpp"
#include "recon/preprocess.hpp"

namespace seamless::app {

namespace {
// A tilted plane with a sphere in front: realistic depth range and discontinuities.
std::vector<float> synthetic_depth(const Intrinsics& K) {
  std::vector<float> z(K.width * K.height);
  const vec3 c{0.1f, 0.f, 1.2f};
  for (int y = 0; y < K.height; ++y)
    for (int x = 0; x < K.width; ++x) {
      vec3 d{(x - K.cx) / K.fx, (y - K.cy) / K.fy, 1.f};
      float b = -2.f * dot(d, c), a = dot(d, d), cc = dot(c, c) - 0.09f, disc = b * b - 4 * a * cc;
      z[y * K.width + x] = disc >= 0 ? (-b - std::sqrt(disc)) / (2 * a) : 2.5f + 0.3f * d.y;
    }
  return z;
}
}  // namespace

std::vector<BenchCase> make_preprocess_bench(const BenchOptions& o) {
  Intrinsics K{517.3f, 516.5f, 318.6f, 255.3f, 640, 480, {0, 0, 0, 0, 0}};
  auto depth = std::make_shared<Image<float>>(Image<float>::from_host(synthetic_depth(K), 640, 480, o.device));
  auto pyr = std::make_shared<FramePyramid>(o.device, K, 3);
  PreprocessParams p;
  return {
      {"pyramid_640x480", [=] { pyr->build(*depth, nullptr, p); }, "bilateral 7x7 + 3 levels + vertices + normals"}};
}

}  // namespace seamless::app
