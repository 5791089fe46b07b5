#include "recon/preprocess.hpp"

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/recon/preprocess.hpp"

namespace seamless {

FramePyramid::FramePyramid(Device d, const Intrinsics& K, int levels) : device_(d) {
  if (levels < 1) throw Error("a depth pyramid needs at least one level");
  for (int l = 0; l < levels; ++l) {
    Intrinsics k = K.level(l);
    levels_.push_back({k, Image<float>(k.width, k.height, d), Image<float>(k.width, k.height, d),
                       Image<vec3>(k.width, k.height, d), Image<vec3>(k.width, k.height, d)});
  }
}

void FramePyramid::build(const Image<float>& raw, const Image<float>* intensity, const PreprocessParams& p) {
  const PyramidLevel& l0 = levels_[0];
  if (raw.width() != l0.K.width || raw.height() != l0.K.height)
    throw Error("depth image is " + std::to_string(raw.width()) + "x" + std::to_string(raw.height()) +
                " but the intrinsics say " + std::to_string(l0.K.width) + "x" + std::to_string(l0.K.height));
  with_exec(device_, [&]<class E>(const E& ex) {
    if (p.bilateral)
      kernels::Preprocess<E>::bilateral_filter(ex, raw.cview(), l0.depth.view(), p.sigma_space, p.sigma_depth, p.radius,
                                               p.bilateral_inline_exp);
    else levels_[0].depth.buffer().copy_from(raw.buffer());
    if (intensity) levels_[0].intensity.buffer().copy_from(intensity->buffer());
    for (std::size_t l = 1; l < levels_.size(); ++l) {
      kernels::Preprocess<E>::pyr_down_depth(ex, levels_[l - 1].depth.cview(), levels_[l].depth.view(),
                                             p.pyramid_max_diff);
      if (intensity)
        kernels::Preprocess<E>::pyr_down_intensity(ex, levels_[l - 1].intensity.cview(), levels_[l].intensity.view());
    }
    for (const PyramidLevel& lv : levels_) {
      kernels::Preprocess<E>::depth_to_vertices(ex, lv.depth.cview(), lv.K, lv.vertices.view());
      kernels::Preprocess<E>::vertices_to_normals(ex, lv.vertices.cview(), lv.normals.view(), p.max_normal_edge);
    }
  });
}

}  // namespace seamless
