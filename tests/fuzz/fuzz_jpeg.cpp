// libFuzzer target: JPEG decoding (src/io/jpeg_io.hpp) and colour images told apart by content.
#include "fuzz_util.hpp"
#include "io/jpeg_io.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  const std::string path = fuzz::put("in.jpg", {reinterpret_cast<const char*>(data), size});
  fuzz::expect_error_or_success([&] { (void)read_jpeg_rgb(path); });
  fuzz::expect_error_or_success([&] { (void)image_format(path); });
  fuzz::expect_error_or_success([&] { (void)read_colour_image(path); });
  return 0;
}
