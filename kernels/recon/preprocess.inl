// Kernel bodies for recon/preprocess.hpp, compiled once per backend.
#include <cmath>

#include "kernels/recon/preprocess.hpp"

namespace seamless::kernels {

// Pixels per work item of the bilateral filter: on the CPU a run of 8 in a row, whose lane loops
// (k below) GCC turns into vector instructions (4 or 8 pixels an instruction); on CUDA one, a
// thread per pixel as before. Each pixel's taps are summed in the same order either way.
template <class Exec> inline constexpr int kBilateralRun = Exec::device == Device::CPU ? 8 : 1;

// The bilateral filter of the G pixels (x0 .. x0 + G - 1, y). Interior: all of their windows lie
// inside the image's columns, so a tap's G readings are G consecutive floats with no bounds test
// (only the first and last run of a row are not). An invalid reading or one outside the image adds
// a weight of +0 (sums of non-negative terms: the same bits as skipping it).
// On x86-64 CPUs the run is also compiled for AVX2 (8 pixels an instruction instead of SSE2's 4), and
// the loader picks the variant the processor has (target_clones). AVX2 without FMA rounds every
// operation as the baseline code does, so both give the same bits. gcc only: clang (the fuzz
// build's compiler) does not multiversion function templates, and gets the SSE2 code alone.
#if !defined(__CUDACC__) && defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define SEAMLESS_BILATERAL_RUN __attribute__((target_clones("avx2", "default")))
#else
#define SEAMLESS_BILATERAL_RUN inline
#endif

// InlineExp: the range weight from exp_nonpositive for every lane, with no branch, so that the lane
// loop vectorises; else libm's expf (CUDA's on the GPU) for the valid taps only, as the filter had
// it: the same bits as one pixel a work item, since the argument, the taps and their order are.
template <int G, bool Interior, bool InlineExp>
SEAMLESS_HD SEAMLESS_BILATERAL_RUN void bilateral_run(View2D<const float> depth, View2D<float> out, int x0, int y,
                                                      int radius, float inv_s2, float inv_d2) {
  float d0[G], sum[G], wsum[G];
  bool any = false;
  for (int k = 0; k < G; ++k) {
    d0[k] = Interior || x0 + k < depth.width ? depth(x0 + k, y) : 0.f;
    any = any || d0[k] > 0.f;
    sum[k] = 0.f;
    wsum[k] = 0.f;
  }
  if (!any) {  // no reading at any of the G pixels (a hole): nothing to filter
    for (int k = 0; k < G; ++k)
      if (Interior || x0 + k < depth.width) out(x0 + k, y) = 0.f;
    return;
  }
  for (int dy = -radius; dy <= radius; ++dy) {
    const int yy = y + dy;
    if (yy < 0 || yy >= depth.height) continue;
    const float* row = &depth(0, yy);
    for (int dx = -radius; dx <= radius; ++dx) {
      const float spatial = -(dx * dx + dy * dy) * inv_s2;
      for (int k = 0; k < G; ++k) {
        const int xx = x0 + k + dx;
        const float d = Interior || (xx >= 0 && xx < depth.width) ? row[xx] : 0.f;
        const bool valid = d > 0.f;
        const float diff = d - d0[k];
        float wgt;
        if constexpr (InlineExp) {
          const float e = exp_nonpositive(spatial - diff * diff * inv_d2);
          wgt = valid ? e : 0.f;
        } else {
          wgt = valid ? expf(spatial - diff * diff * inv_d2) : 0.f;
        }
        sum[k] += wgt * (valid ? d : 0.f);
        wsum[k] += wgt;
      }
    }
  }
  for (int k = 0; k < G; ++k)
    if (Interior || x0 + k < depth.width) out(x0 + k, y) = d0[k] > 0.f ? sum[k] / wsum[k] : 0.f;
}

template <Executor Exec>
void Preprocess<Exec>::bilateral_filter(const Exec& ex, View2D<const float> depth, View2D<float> out, float sigma_space,
                                        float sigma_depth, int radius, bool inline_exp) {
  constexpr int G = kBilateralRun<Exec>;
  const float inv_s2 = 0.5f / (sigma_space * sigma_space);
  const float inv_d2 = 0.5f / (sigma_depth * sigma_depth);
  const int runs = (depth.width + G - 1) / G;
  ex.for_each(static_cast<std::int64_t>(runs) * depth.height, [=] SEAMLESS_HD(std::int64_t i) {
    const int x0 = static_cast<int>(i % runs) * G, y = static_cast<int>(i / runs);
    const bool interior = x0 >= radius && x0 + G - 1 + radius < depth.width;
    if (interior && inline_exp) bilateral_run<G, true, true>(depth, out, x0, y, radius, inv_s2, inv_d2);
    else if (interior) bilateral_run<G, true, false>(depth, out, x0, y, radius, inv_s2, inv_d2);
    else if (inline_exp) bilateral_run<G, false, true>(depth, out, x0, y, radius, inv_s2, inv_d2);
    else bilateral_run<G, false, false>(depth, out, x0, y, radius, inv_s2, inv_d2);
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
    out(x, y) = a < 0.f || b < 0.f || c < 0.f || d < 0.f ? -1.f : 0.25f * (a + b + c + d);
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
