// JPEG colour images with libjpeg (Debian libjpeg62-turbo-dev, the libjpeg-turbo implementation of
// the IJG API), and reading a colour image by its content: PNG or JPEG, whatever the file is called.
// Errors (missing file, truncated or corrupt data, a colour space libjpeg cannot turn into RGB)
// throw seamless::Error naming the file.
#pragma once
#include <string>

#include "core/buffer.hpp"
#include "core/math.hpp"

namespace seamless {

// 8-bit RGB; greyscale JPEGs are expanded to RGB by libjpeg. A host image.
Image<uchar3> read_jpeg_rgb(const std::string& path);
// Baseline JPEG, 4:2:0 chroma subsampling (libjpeg's default), quality 1..100.
void write_jpeg_rgb(const std::string& path, const Image<uchar3>& image, int quality = 95);

enum class ImageFormat { png, jpeg, unknown };
// From the file's first bytes (PNG's 8-byte signature, JPEG's SOI marker FF D8 FF), not its name:
// folders exported by other tools have .png files holding JPEG data and the other way round.
// Throws seamless::Error when the file cannot be opened.
ImageFormat image_format(const std::string& path);

// A colour image in either format (decided by image_format), as 8-bit RGB; anything else is an
// Error that names the file and what its first bytes look like.
Image<uchar3> read_colour_image(const std::string& path);

}  // namespace seamless
