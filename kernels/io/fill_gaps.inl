// Kernel bodies for io/fill_gaps.hpp, compiled once per backend.
#include <cmath>

#include "kernels/io/fill_gaps.hpp"

namespace seamless::kernels {

template <Executor Exec>
void FillGaps<Exec>::fill_depth_gaps(const Exec& ex, View2D<const float> in, View2D<float> out, float max_rel_diff) {
  const int w = out.width;
  ex.for_each(out.count(), [=] SEAMLESS_HD(std::int64_t i) {
    int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
    out(x, y) = fill_gap_at(in, x, y, max_rel_diff);
  });
}

}  // namespace seamless::kernels
