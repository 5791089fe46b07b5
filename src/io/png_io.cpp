// libpng's classic API with setjmp error handling. Everything that must survive a longjmp lives on
// the heap (PngState), never in a non-volatile local changed after setjmp.
#include "io/png_io.hpp"

#include <png.h>

#include <bit>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "core/error.hpp"

namespace seamless {
namespace {

enum class Want { Info, U16, U8, RGB };

struct PngState {
  jmp_buf jb;
  std::string libpng_message;
  std::string format_problem;  // set when the image is fine but not what was asked for
  PngInfo info;
  std::vector<std::uint8_t> pixels;
  std::vector<png_bytep> rows;
};

void on_png_error(png_structp png, png_const_charp msg) {
  auto* s = static_cast<PngState*>(png_get_error_ptr(png));
  s->libpng_message = msg;
  std::longjmp(s->jb, 1);
}
void on_png_warning(png_structp, png_const_charp) {}

using File = std::unique_ptr<FILE, int (*)(FILE*)>;

File open_png_file(const std::string& path, const char* mode, const char* what) {
  FILE* f = std::fopen(path.c_str(), mode);
  if (!f) {
    std::string msg = std::string("cannot ") + what + " PNG file '" + path + "': " + std::strerror(errno);
    if (mode[0] == 'r') throw InputError(msg);  // a missing input; a file we cannot create is not one
    throw Error(msg);
  }
  return File(f, std::fclose);
}

std::string describe(const PngInfo& i) {
  const char* kind[] = {"?", "grayscale", "grayscale+alpha", "RGB", "RGBA"};
  return std::to_string(i.bit_depth) + "-bit " + kind[i.channels < 5 ? i.channels : 0];
}

}  // namespace

void check_image_size(std::int64_t width, std::int64_t height, const std::string& what) {
  if (width <= 0 || height <= 0 || width * height > kMaxImagePixels)
    throw InputError(what + " is " + std::to_string(width) + "x" + std::to_string(height) +
                     " pixels, more than the readers decode (" + std::to_string(kMaxImagePixels) +
                     "): a corrupt header?");
}

namespace {

// Chooses libpng transforms for `want`; returns a message when the file cannot be read that way.
std::string set_transforms(png_structp png, int color_type, int bit_depth, Want want, const PngInfo& info) {
  bool gray = color_type == PNG_COLOR_TYPE_GRAY;
  if (want == Want::U16) {
    if (!gray || bit_depth != 16)
      return "is " + describe(info) + ", expected 16-bit grayscale (e.g. a TUM depth image)";
    if (std::endian::native == std::endian::little) png_set_swap(png);  // PNG stores big-endian
  } else if (want == Want::U8) {
    if (!gray || bit_depth != 8) return "is " + describe(info) + ", expected 8-bit grayscale";
  } else if (want == Want::RGB) {
    if (color_type == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color_type == PNG_COLOR_TYPE_GRAY || color_type == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
    if (bit_depth == 16) png_set_strip_16(png);
    if (bit_depth < 8) png_set_packing(png);
    if (color_type & PNG_COLOR_MASK_ALPHA) png_set_strip_alpha(png);
    png_set_strip_alpha(png);  // tRNS chunks expanded from palettes
  }
  return {};
}

// Reads `path` into s->pixels (tightly packed rows). Throws Error naming the file.
void read_png(const std::string& path, Want want, PngState* s) {
  File f = open_png_file(path, "rb", "open");
  png_byte sig[8];
  if (std::fread(sig, 1, 8, f.get()) != 8 || png_sig_cmp(sig, 0, 8))
    throw InputError("'" + path + "' is not a PNG file (bad signature; empty or truncated?)");
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, s, on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) throw InputError("libpng could not allocate its read structures for '" + path + "'");
  if (setjmp(s->jb)) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError("PNG file '" + path + "' is truncated or corrupt (libpng: " + s->libpng_message + ")");
  }
  png_init_io(png, f.get());
  png_set_sig_bytes(png, 8);
  png_read_info(png, info);
  int color_type = png_get_color_type(png, info), bit_depth = png_get_bit_depth(png, info);
  s->info.width = static_cast<int>(png_get_image_width(png, info));
  s->info.height = static_cast<int>(png_get_image_height(png, info));
  s->info.bit_depth = bit_depth;
  s->info.channels = color_type == PNG_COLOR_TYPE_PALETTE ? 3 : png_get_channels(png, info);
  if (want != Want::Info && static_cast<std::int64_t>(s->info.width) * s->info.height > kMaxImagePixels) {
    png_destroy_read_struct(&png, &info, nullptr);
    check_image_size(s->info.width, s->info.height, "PNG file '" + path + "'");
  }
  if (want != Want::Info) s->format_problem = set_transforms(png, color_type, bit_depth, want, s->info);
  if (want != Want::Info && s->format_problem.empty()) {
    png_read_update_info(png, info);
    std::size_t row_bytes = png_get_rowbytes(png, info);
    s->pixels.resize(row_bytes * s->info.height);
    s->rows.resize(s->info.height);
    for (int y = 0; y < s->info.height; ++y) s->rows[y] = s->pixels.data() + row_bytes * y;
    png_read_image(png, s->rows.data());
    png_read_end(png, nullptr);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  if (!s->format_problem.empty()) throw InputError("PNG file '" + path + "' " + s->format_problem);
}

template <class T> Image<T> to_image(const PngState& s, const std::string& path) {
  std::size_t n = static_cast<std::size_t>(s.info.width) * s.info.height;
  if (s.pixels.size() != n * sizeof(T))
    throw InputError("PNG file '" + path + "': unexpected decoded size (internal error)");
  Image<T> im(s.info.width, s.info.height, Device::CPU);
  std::memcpy(im.buffer().data(), s.pixels.data(), s.pixels.size());
  return im;
}

void write_png(const std::string& path, int w, int h, int bit_depth, int color_type, const void* data,
               std::size_t row_bytes) {
  File f = open_png_file(path, "wb", "create");
  auto s = std::make_unique<PngState>();
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, s.get(), on_png_error, on_png_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) throw Error("libpng could not allocate its write structures for '" + path + "'");
  if (setjmp(s->jb)) {
    png_destroy_write_struct(&png, &info);
    throw Error("cannot write PNG file '" + path + "' (libpng: " + s->libpng_message + ")");
  }
  s->rows.resize(h);
  for (int y = 0; y < h; ++y) s->rows[y] = const_cast<png_bytep>(static_cast<const png_byte*>(data) + row_bytes * y);
  png_init_io(png, f.get());
  // Depth PNGs are written often (recording at 30 Hz): fast compression is the right trade-off.
  png_set_compression_level(png, 1);
  png_set_IHDR(png, info, w, h, bit_depth, color_type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  png_write_info(png, info);
  if (bit_depth == 16 && std::endian::native == std::endian::little) png_set_swap(png);
  png_write_image(png, s->rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  if (std::fflush(f.get()) != 0) throw Error("cannot write PNG file '" + path + "': " + std::strerror(errno));
}

template <class T> void check_host(const Image<T>& im, const std::string& path) {
  if (im.device() != Device::CPU) throw Error("write_png: image for '" + path + "' must be a host image");
  if (im.width() <= 0 || im.height() <= 0) throw Error("write_png: image for '" + path + "' is empty");
}

}  // namespace

PngInfo png_info(const std::string& path) {
  auto s = std::make_unique<PngState>();
  read_png(path, Want::Info, s.get());
  return s->info;
}

Image<std::uint16_t> read_png_u16(const std::string& path) {
  auto s = std::make_unique<PngState>();
  read_png(path, Want::U16, s.get());
  return to_image<std::uint16_t>(*s, path);
}

Image<std::uint8_t> read_png_u8(const std::string& path) {
  auto s = std::make_unique<PngState>();
  read_png(path, Want::U8, s.get());
  return to_image<std::uint8_t>(*s, path);
}

Image<uchar3> read_png_rgb(const std::string& path) {
  auto s = std::make_unique<PngState>();
  read_png(path, Want::RGB, s.get());
  return to_image<uchar3>(*s, path);
}

void write_png_u16(const std::string& path, const Image<std::uint16_t>& im) {
  check_host(im, path);
  write_png(path, im.width(), im.height(), 16, PNG_COLOR_TYPE_GRAY, im.buffer().data(), 2 * im.width());
}

void write_png_u8(const std::string& path, const Image<std::uint8_t>& im) {
  check_host(im, path);
  write_png(path, im.width(), im.height(), 8, PNG_COLOR_TYPE_GRAY, im.buffer().data(), im.width());
}

void write_png_rgb(const std::string& path, const Image<uchar3>& im) {
  check_host(im, path);
  write_png(path, im.width(), im.height(), 8, PNG_COLOR_TYPE_RGB, im.buffer().data(), 3 * im.width());
}

}  // namespace seamless
