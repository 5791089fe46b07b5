#include "io/rgbd_pair.hpp"

#include "core/error.hpp"
#include "io/depth_scale.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/jpeg_io.hpp"
#include "io/png_io.hpp"

namespace seamless {

namespace {
std::string size_text(int w, int h) { return std::to_string(w) + "x" + std::to_string(h); }
}  // namespace

RawRgbdPair read_rgbd_pair(const std::string& depth_path, const std::string& colour_path, const Intrinsics& K,
                           bool flip_x, bool flip_y) {
  RawRgbdPair p{read_png_u16(depth_path), read_colour_image(colour_path)};
  flip_image(p.depth, flip_x, flip_y), flip_image(p.colour, flip_x, flip_y);  // a negative focal length
  const Image<std::uint16_t>& d = p.depth;
  if (d.width() != K.width || d.height() != K.height)
    throw InputError("depth image '" + depth_path + "' is " + size_text(d.width(), d.height()) +
                     " but input.intrinsics says " + size_text(K.width, K.height));
  if (p.colour.width() != d.width() || p.colour.height() != d.height())
    throw InputError("colour image '" + colour_path + "' is " + size_text(p.colour.width(), p.colour.height()) +
                     ", its depth image '" + depth_path + "' " + size_text(d.width(), d.height()) +
                     " (the depth must be registered to the colour camera)");
  return p;
}

void decode_depth(const Image<std::uint16_t>& raw, double scale, const std::string& depth_path, bool fill_gaps,
                  bool first_frame, Image<float>& gap_scratch, DepthScaleCheck& scale_check, Image<float>& out) {
  if (fill_gaps && gap_scratch.width() != raw.width())
    gap_scratch = Image<float>(raw.width(), raw.height(), Device::CPU);
  Image<float>& decoded = fill_gaps ? gap_scratch : out;
  const float inv = static_cast<float>(1.0 / scale);
  const std::uint16_t* r = raw.buffer().data();
  float* d = decoded.buffer().data();
  for (std::int64_t k = 0; k < raw.buffer().size(); ++k) d[k] = r[k] == 65535 ? 0.f : r[k] * inv;
  if (fill_gaps) fill_depth_gaps_host(gap_scratch, out);
  if (!fill_gaps && first_frame) hint_depth_gaps(out, depth_path);
  check_median_depth(out, scale, depth_path);
  scale_check.check(raw, depth_path);
}

}  // namespace seamless
