// libFuzzer target: PNG decoding (src/io/png_io.hpp) as depth (16-bit), mask (8-bit) and colour,
// and colour images told apart by content (read_colour_image).
#include "fuzz_util.hpp"
#include "io/jpeg_io.hpp"
#include "io/png_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  const std::string path = fuzz::put("in.png", {reinterpret_cast<const char*>(data), size});
  fuzz::expect_error_or_success([&] { (void)png_info(path); });
  fuzz::expect_error_or_success([&] { (void)read_png_u16(path); });
  fuzz::expect_error_or_success([&] { (void)read_png_u8(path); });
  fuzz::expect_error_or_success([&] { (void)read_png_rgb(path); });
  fuzz::expect_error_or_success([&] { (void)read_colour_image(path); });
  return 0;
}
