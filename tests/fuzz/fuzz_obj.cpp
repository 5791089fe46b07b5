// libFuzzer target: the OBJ reader of rigid mesh bodies (src/physics/builders.cpp), through
// voxelize_obj on a grid of at most 10 x 10 x 10 cells (the mesh is fitted into 0.5 m at 5 cm).
#include "fuzz_util.hpp"
#include "physics/builders.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  const std::string path = fuzz::put("in.obj", {reinterpret_cast<const char*>(data), size});
  fuzz::expect_error_or_success([&] { (void)voxelize_obj(path, 0.05f, vec3{0.5f, 0.5f, 0.5f}); });
  return 0;
}
