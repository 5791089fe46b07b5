// libjpeg's classic API with setjmp error handling (its default error handler calls exit()).
// Everything that must survive a longjmp lives on the heap (JpegState), never in a non-volatile local
// changed after setjmp.
#include "io/jpeg_io.hpp"

// jpeglib.h needs FILE and size_t declared before it.
#include <cstddef>
#include <cstdio>
// clang-format off
#include <jpeglib.h>
#include <jerror.h>
// clang-format on

#include <cerrno>
#include <csetjmp>
#include <cstring>
#include <memory>
#include <vector>

#include "core/error.hpp"
#include "io/png_io.hpp"

namespace seamless {
namespace {

struct JpegState {
  jpeg_error_mgr mgr;  // first member: libjpeg hands our handlers a pointer to it
  jmp_buf jb;
  std::string message;
  bool truncated = false;
};

void on_jpeg_error(j_common_ptr c) {
  auto* s = reinterpret_cast<JpegState*>(c->err);
  char buf[JMSG_LENGTH_MAX];
  c->err->format_message(c, buf);
  s->message = buf;
  std::longjmp(s->jb, 1);
}

// Warnings (level -1) are corrupt-data notices; libjpeg goes on decoding. A premature end of the
// file is one of them: libjpeg pads the missing rows with grey, which we must not pass on as data.
void on_jpeg_message(j_common_ptr c, int level) {
  auto* s = reinterpret_cast<JpegState*>(c->err);
  if (level < 0 && c->err->msg_code == JWRN_JPEG_EOF) s->truncated = true;
}

using File = std::unique_ptr<FILE, int (*)(FILE*)>;

File open_jpeg_file(const std::string& path, const char* mode, const char* what) {
  FILE* f = std::fopen(path.c_str(), mode);
  if (!f) throw InputError(std::string("cannot ") + what + " image file '" + path + "': " + std::strerror(errno));
  return File(f, std::fclose);
}

void install_handlers(JpegState& s) {
  jpeg_std_error(&s.mgr);
  s.mgr.error_exit = on_jpeg_error;
  s.mgr.emit_message = on_jpeg_message;
}

}  // namespace

Image<uchar3> read_jpeg_rgb(const std::string& path) {
  File f = open_jpeg_file(path, "rb", "open");
  auto s = std::make_unique<JpegState>();
  auto d = std::make_unique<jpeg_decompress_struct>();
  install_handlers(*s);
  d->err = &s->mgr;
  auto img = std::make_unique<Image<uchar3>>();
  if (setjmp(s->jb)) {
    jpeg_destroy_decompress(d.get());
    throw InputError("JPEG file '" + path + "' is truncated, corrupt or not decodable as RGB (libjpeg: " + s->message +
                     ")");
  }
  jpeg_create_decompress(d.get());
  jpeg_stdio_src(d.get(), f.get());
  jpeg_read_header(d.get(), TRUE);
  if (static_cast<std::int64_t>(d->image_width) * d->image_height > kMaxImagePixels) {
    const std::int64_t w = d->image_width, h = d->image_height;
    jpeg_destroy_decompress(d.get());
    check_image_size(w, h, "JPEG file '" + path + "'");
  }
  d->out_color_space = JCS_RGB;  // libjpeg converts YCbCr and greyscale; CMYK is an error above
  jpeg_start_decompress(d.get());
  if (const int channels = d->output_components; channels != 3) {  // not with JCS_RGB; guards the rows below
    jpeg_destroy_decompress(d.get());
    throw InputError("JPEG file '" + path + "' decodes to " + std::to_string(channels) + " channels, not RGB");
  }
  *img = Image<uchar3>(static_cast<int>(d->output_width), static_cast<int>(d->output_height), Device::CPU);
  auto* base = reinterpret_cast<JSAMPLE*>(img->buffer().data());
  while (d->output_scanline < d->output_height) {
    JSAMPROW row = base + static_cast<std::size_t>(d->output_scanline) * d->output_width * 3;
    jpeg_read_scanlines(d.get(), &row, 1);
  }
  jpeg_finish_decompress(d.get());
  jpeg_destroy_decompress(d.get());
  if (s->truncated) throw InputError("JPEG file '" + path + "' is truncated (libjpeg: premature end of data)");
  return std::move(*img);
}

void write_jpeg_rgb(const std::string& path, const Image<uchar3>& im, int quality) {
  if (im.device() != Device::CPU) throw Error("write_jpeg_rgb: image for '" + path + "' must be a host image");
  if (im.width() <= 0 || im.height() <= 0) throw Error("write_jpeg_rgb: image for '" + path + "' is empty");
  if (quality < 1 || quality > 100)
    throw Error("write_jpeg_rgb: quality " + std::to_string(quality) + " for '" + path + "' is outside 1..100");
  File f = open_jpeg_file(path, "wb", "create");
  auto s = std::make_unique<JpegState>();
  auto c = std::make_unique<jpeg_compress_struct>();
  install_handlers(*s);
  c->err = &s->mgr;
  if (setjmp(s->jb)) {
    jpeg_destroy_compress(c.get());
    throw Error("cannot write JPEG file '" + path + "' (libjpeg: " + s->message + ")");
  }
  jpeg_create_compress(c.get());
  jpeg_stdio_dest(c.get(), f.get());
  c->image_width = static_cast<JDIMENSION>(im.width());
  c->image_height = static_cast<JDIMENSION>(im.height());
  c->input_components = 3;
  c->in_color_space = JCS_RGB;
  jpeg_set_defaults(c.get());
  jpeg_set_quality(c.get(), quality, TRUE);
  jpeg_start_compress(c.get(), TRUE);
  const auto* base = reinterpret_cast<const JSAMPLE*>(im.buffer().data());
  while (c->next_scanline < c->image_height) {
    JSAMPROW row = const_cast<JSAMPLE*>(base + static_cast<std::size_t>(c->next_scanline) * im.width() * 3);
    jpeg_write_scanlines(c.get(), &row, 1);
  }
  jpeg_finish_compress(c.get());
  jpeg_destroy_compress(c.get());
  if (std::fflush(f.get()) != 0) throw Error("cannot write JPEG file '" + path + "': " + std::strerror(errno));
}

ImageFormat image_format(const std::string& path) {
  File f = open_jpeg_file(path, "rb", "open");
  unsigned char b[8] = {};
  std::size_t n = std::fread(b, 1, sizeof b, f.get());
  static const unsigned char png_sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (n == 8 && std::memcmp(b, png_sig, 8) == 0) return ImageFormat::png;
  if (n >= 3 && b[0] == 0xFF && b[1] == 0xD8 && b[2] == 0xFF) return ImageFormat::jpeg;  // SOI, then a marker
  return ImageFormat::unknown;
}

Image<uchar3> read_colour_image(const std::string& path) {
  switch (image_format(path)) {
    case ImageFormat::png: return read_png_rgb(path);
    case ImageFormat::jpeg: return read_jpeg_rgb(path);
    case ImageFormat::unknown: break;
  }
  throw InputError("colour image '" + path +
                   "' is neither PNG nor JPEG (its first bytes are no PNG signature and no "
                   "JPEG start-of-image marker; empty, truncated or another format?)");
}

}  // namespace seamless
