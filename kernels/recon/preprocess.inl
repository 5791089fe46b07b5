// Kernel bodies for recon/preprocess.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/preprocess.hpp"

namespace seamless::kernels {

template <Executor Exec>
void Preprocess<Exec>::bilateral_filter(const Exec& ex, View2D<const float> depth, View2D<float> out, float sigma_space,
                                        float sigma_depth, int radius) {
  const float inv_s2 = 0.5f / (sigma_space * sigma_space);
  const float inv_d2 = 0.5f / (sigma_depth * sigma_depth);
  const int w = depth.width;
  ex.for_each(depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    float d0 = depth(x, y);
    if (!(d0 > 0.f)) {
      out(x, y) = 0.f;
      return;
    }
    float sum = 0.f, wsum = 0.f;
    for (int dy = -radius; dy <= radius; ++dy)
      for (int dx = -radius; dx <= radius; ++dx) {
        int xx = x + dx, yy = y + dy;
        if (!depth.inside(xx, yy)) continue;
        float d = depth(xx, yy);
        if (!(d > 0.f)) continue;
        float wgt = expf(-(dx * dx + dy * dy) * inv_s2 - (d - d0) * (d - d0) * inv_d2);
        sum += wgt * d;
        wsum += wgt;
      }
    out(x, y) = sum / wsum;
  });
}

template <Executor Exec>
void Preprocess<Exec>::pyr_down_depth(const Exec& ex, View2D<const float> in, View2D<float> out, float max_diff) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    float ref = 0.f, sum = 0.f;
    int n = 0;
    for (int k = 0; k < 4; ++k) {
      int xx = 2 * x + (k & 1), yy = 2 * y + (k >> 1);
      if (!in.inside(xx, yy)) continue;
      float d = in(xx, yy);
      if (!(d > 0.f)) continue;
      if (n == 0) ref = d;
      if (fabsf(d - ref) <= max_diff) {
        sum += d;
        ++n;
      }
    }
    out(x, y) = n ? sum / n : 0.f;
  });
}

template <Executor Exec>
void Preprocess<Exec>::pyr_down_intensity(const Exec& ex, View2D<const float> in, View2D<float> out) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    const float a = in(2 * x, 2 * y), b = in(2 * x + 1, 2 * y), c = in(2 * x, 2 * y + 1), d = in(2 * x + 1, 2 * y + 1);
    out(x, y) = fminf(fminf(a, b), fminf(c, d)) < 0.f ? -1.f : 0.25f * (a + b + c + d);
  });
}

template <Executor Exec>
void Preprocess<Exec>::depth_to_vertices(const Exec& ex, View2D<const float> depth, Intrinsics K,
                                         View2D<vec3> vertices) {
  const int w = depth.width;
  ex.for_each(depth.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    float d = depth(x, y);
    vertices(x, y) = d > 0.f ? K.unproject(static_cast<float>(x), static_cast<float>(y), d) : vec3{0.f, 0.f, 0.f};
  });
}

template <Executor Exec>
void Preprocess<Exec>::vertices_to_normals(const Exec& ex, View2D<const vec3> vertices, View2D<vec3> normals,
                                           float max_edge) {
  const int w = vertices.width;
  const float max_edge2 = max_edge * max_edge;
  ex.for_each(vertices.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    vec3 n{0.f, 0.f, 0.f};
    if (x + 1 < vertices.width && y + 1 < vertices.height) {
      vec3 p = vertices(x, y), r = vertices(x + 1, y), d = vertices(x, y + 1);
      if (p.z > 0.f && r.z > 0.f && d.z > 0.f) {
        vec3 a = r - p, b = d - p;
        if (length2(a) < max_edge2 && length2(b) < max_edge2) {
          n = normalize(cross(a, b));
          if (dot(n, p) > 0.f) n = -n;  // face the camera at the origin
        }
      }
    }
    normals(x, y) = n;
  });
}

}  // namespace seamless::kernels
