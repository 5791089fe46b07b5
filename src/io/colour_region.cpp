#include "io/colour_region.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "io/input_params.hpp"
#include "io/intrinsics_presets.hpp"
#include "kernels/io/undistort.hpp"

namespace seamless {

namespace {

// Summed-area table of the unset pixels: the count inside any rectangle in four lookups.
struct HoleCount {
  int w, h;
  std::vector<std::int64_t> s;  // (w + 1) x (h + 1), s(x, y) = unset pixels above and left of (x, y)
  HoleCount(const std::vector<std::uint8_t>& mask, int w_, int h_)
      : w(w_), h(h_), s(static_cast<std::size_t>(w_ + 1) * (h_ + 1), 0) {
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        at(x + 1, y + 1) = at(x, y + 1) + at(x + 1, y) - at(x, y) + (mask[std::size_t(y) * w + x] ? 0 : 1);
  }
  std::int64_t& at(int x, int y) { return s[std::size_t(y) * (w + 1) + x]; }
  std::int64_t in(int x, int y, int rw, int rh) {
    return at(x + rw, y + rh) - at(x, y + rh) - at(x + rw, y) + at(x, y);
  }
};

// The hole-free position of a rw x rh rectangle nearest the centre, if any.
bool place(HoleCount& holes, int rw, int rh, PixelRect& out) {
  double best = std::numeric_limits<double>::max();
  for (int y = 0; y + rh <= holes.h; ++y)
    for (int x = 0; x + rw <= holes.w; ++x) {
      if (holes.in(x, y, rw, rh) != 0) continue;
      const double dx = x + 0.5 * rw - 0.5 * holes.w, dy = y + 0.5 * rh - 0.5 * holes.h;
      if (dx * dx + dy * dy < best) best = dx * dx + dy * dy, out = {x, y, rw, rh};
    }
  return best != std::numeric_limits<double>::max();
}

}  // namespace

PixelRect largest_rect_of_aspect(const std::vector<std::uint8_t>& mask, int w, int h) {
  HoleCount holes(mask, w, h);
  auto width_of = [&](int rh) { return std::clamp(static_cast<int>(std::lround(double(rh) * w / h)), 1, w); };
  // A smaller rectangle fits wherever a larger one does: bisect on the height.
  PixelRect best{};
  int lo = 1, hi = h;
  while (lo <= hi) {
    const int mid = (lo + hi) / 2;
    PixelRect r;
    if (place(holes, width_of(mid), mid, r)) best = r, lo = mid + 1;
    else hi = mid - 1;
  }
  return best;
}

PixelRect undistorted_colour_region(const Intrinsics& lens) {
  const int w = lens.width, h = lens.height;
  if (std::all_of(std::begin(lens.dist), std::end(lens.dist), [](float d) { return d == 0.f; })) return {0, 0, w, h};
  std::vector<std::uint8_t> mask(static_cast<std::size_t>(w) * h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      mask[std::size_t(y) * w + x] =
          kernels::colour_lookup_inside(kernels::distort_pixel(lens, float(x), float(y)), w, h) ? 1 : 0;
  return largest_rect_of_aspect(mask, w, h);
}

PixelRect input_colour_region(const InputParams& input) {
  if (input.source != InputSource::tum || !input.undistort) return {};
  const Intrinsics K = resolve_intrinsics(input.intrinsics, input.path).K;
  if (K.dist[0] == 0.f) return {};  // as TumSource::load_frame decides
  return undistorted_colour_region(K);
}

}  // namespace seamless
