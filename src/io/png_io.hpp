// PNG reading and writing with libpng. Errors (missing file, truncated or corrupt data, a bit depth
// or colour type other than the one asked for) throw seamless::Error naming the file.
#pragma once
#include <cstdint>
#include <string>

#include "core/buffer.hpp"
#include "core/math.hpp"

namespace seamless {

struct PngInfo {
  int width = 0, height = 0;
  int bit_depth = 0;  // per channel
  int channels = 0;   // 1 gray, 2 gray+alpha, 3 RGB, 4 RGBA (palette images report 3)
};

PngInfo png_info(const std::string& path);

// The largest image the readers decode (PNG and JPEG): 8192 x 8192 pixels, four times the largest
// depth or colour camera image in use (4096 x 3072); a corrupt header that claims more would make
// them allocate gigabytes before the data is found missing (found by fuzzing).
inline constexpr std::int64_t kMaxImagePixels = std::int64_t{8192} * 8192;
// Throws an InputError naming `what` (the file) when width x height is larger or not positive.
void check_image_size(std::int64_t width, std::int64_t height, const std::string& what);

// 16-bit grayscale only (TUM depth); an 8-bit image is an error (it cannot hold depth).
Image<std::uint16_t> read_png_u16(const std::string& path);
// 8-bit grayscale only.
Image<std::uint8_t> read_png_u8(const std::string& path);
// 8-bit colour: RGB, or RGBA / palette / gray converted to RGB.
Image<uchar3> read_png_rgb(const std::string& path);

// Images are host (Device::CPU) images.
void write_png_u16(const std::string& path, const Image<std::uint16_t>& image);
void write_png_u8(const std::string& path, const Image<std::uint8_t>& image);
void write_png_rgb(const std::string& path, const Image<uchar3>& image);

}  // namespace seamless
