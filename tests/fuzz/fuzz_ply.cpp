// libFuzzer target: the PLY mesh reader (src/recon/ply.hpp). A mesh that loads must be usable:
// every triangle's indices name one of its vertices.
#include <cstdlib>

#include "fuzz_util.hpp"
#include "recon/ply.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  const std::string path = fuzz::put("in.ply", {reinterpret_cast<const char*>(data), size});
  fuzz::expect_error_or_success([&] {
    Mesh m = read_ply(path);
    const auto n = static_cast<int>(m.positions.size());
    for (const int3& t : m.triangles)
      if (t.x < 0 || t.y < 0 || t.z < 0 || t.x >= n || t.y >= n || t.z >= n) std::abort();
  });
  return 0;
}
