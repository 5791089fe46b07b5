// Closing the one-pixel gaps of registered depth. Depth that was registered to the colour camera by
// projecting each depth pixel forward (the depth camera has another resolution or viewpoint)
// leaves pixels that no depth pixel landed on: isolated zeros, whole empty rows and columns, between
// measurements of one surface (the frames_box_50 sample: a third of the pixels are such gaps).
// A gap is filled only where two opposite neighbours (left/right, up/down or a diagonal pair) both
// have depth and agree to `max_rel_diff` of their depth: then the pixel lies between two samples
// of one surface and their mean is the linear interpolation at its centre. Next to a depth
// discontinuity the pairs disagree and the pixel stays empty, as does a pixel of a wider hole that
// no line through it crosses with measurements on both sides.
#pragma once
#include <cmath>

#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

// Two samples two pixels apart on one plane differ relatively by 2 tan(theta) / f at incidence theta
// (f in pixels): at f ~ 600 px, 3% still admits surfaces seen at 84 degrees, while a step of 3% of
// the depth (1.2 cm at 0.4 m: an object's edge over a table) is a discontinuity and not filled.
inline constexpr float kFillGapsMaxRelDiff = 0.03f;

SEAMLESS_HD inline float fill_gap_at(View2D<const float> in, int x, int y, float max_rel_diff) {
  const float d = in(x, y);
  if (d > 0.f) return d;
  const int pairs[4][2] = {{1, 0}, {0, 1}, {1, 1}, {1, -1}};
  float sum = 0.f;
  int n = 0;
  for (const auto& p : pairs) {
    const int ax = x - p[0], ay = y - p[1], bx = x + p[0], by = y + p[1];
    if (!in.inside(ax, ay) || !in.inside(bx, by)) continue;
    const float a = in(ax, ay), b = in(bx, by);
    if (a <= 0.f || b <= 0.f || fabsf(a - b) > max_rel_diff * min_of(a, b)) continue;
    sum += 0.5f * (a + b);
    ++n;
  }
  return n > 0 ? sum / static_cast<float>(n) : 0.f;
}

template <Executor Exec> struct FillGaps {
  // out = in with its one-pixel gaps filled (out must not alias in).
  static void fill_depth_gaps(const Exec& ex, View2D<const float> in, View2D<float> out, float max_rel_diff);
};

}  // namespace seamless::kernels
