// Every seed of the fuzz corpora (corpus/<target>/) and every input that once broke a reader
// (regressions/<target>/, one file per bug, named after it) through the fuzz targets' bodies
// (fuzz_targets.hpp): each must be accepted, or rejected with a seamless::Error. A crash or a
// sanitizer report ends the test binary; scripts/sanitize runs it under ASan and UBSan.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "fuzz_targets.hpp"

namespace {

namespace fs = std::filesystem;
using Target = void (*)(const std::uint8_t*, std::size_t);

std::vector<fs::path> inputs(const std::string& kind, const std::string& target) {
  std::vector<fs::path> files;
  const fs::path dir = fs::path(SEAMLESS_FUZZ_DIR) / kind / target;
  if (fs::is_directory(dir))
    for (const fs::directory_entry& e : fs::directory_iterator(dir))
      if (e.is_regular_file()) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

// Returns the number of seeds.
std::size_t run_all(const std::string& target, Target f) {
  for (const std::string kind : {"corpus", "regressions"})
    for (const fs::path& p : inputs(kind, target)) {
      SCOPED_TRACE(p.string());
      std::ifstream in(p, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      EXPECT_NO_THROW(f(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()));
    }
  return inputs("corpus", target).size();
}

}  // namespace

// Each target has seeds (an empty corpus would fuzz from nothing and test nothing here).
TEST(FuzzRegressions, Config) { EXPECT_GT(run_all("config", seamless::fuzz::config), 0u); }
TEST(FuzzRegressions, Tum) { EXPECT_GT(run_all("tum", seamless::fuzz::tum), 0u); }
TEST(FuzzRegressions, Frames) { EXPECT_GT(run_all("frames", seamless::fuzz::frames), 0u); }
TEST(FuzzRegressions, Fakenect) { EXPECT_GT(run_all("fakenect", seamless::fuzz::fakenect), 0u); }
TEST(FuzzRegressions, Png) { EXPECT_GT(run_all("png", seamless::fuzz::png), 0u); }
TEST(FuzzRegressions, Jpeg) { EXPECT_GT(run_all("jpeg", seamless::fuzz::jpeg), 0u); }
TEST(FuzzRegressions, Ply) { EXPECT_GT(run_all("ply", seamless::fuzz::ply), 0u); }
TEST(FuzzRegressions, Obj) { EXPECT_GT(run_all("obj", seamless::fuzz::obj), 0u); }

// Image headers that claim more pixels than any camera gives are rejected before anything is
// allocated (they made the decoders ask for 10-20 GB: out of memory under the fuzzer).
TEST(FuzzRegressions, HugeImageHeadersAreInputErrors) {
  const fs::path dir = fs::path(SEAMLESS_FUZZ_DIR) / "regressions";
  const std::string png = (dir / "png" / "header_claims_100000x100000").string();
  const std::string jpg = (dir / "jpeg" / "header_claims_60000x60000").string();
  for (auto read : {+[](const std::string& p) { (void)seamless::read_png_u16(p); },
                    +[](const std::string& p) { (void)seamless::read_colour_image(p); }}) {
    try {
      read(png);
      ADD_FAILURE() << "no error for " << png;
    } catch (const seamless::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("is 100000x100000 pixels, more than the readers decode"), std::string::npos)
          << e.what();
    }
  }
  try {
    (void)seamless::read_jpeg_rgb(jpg);
    ADD_FAILURE() << "no error for " << jpg;
  } catch (const seamless::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is 60000x60000 pixels"), std::string::npos) << e.what();
  }
  // png_info reads the header only: it reports the size as it is.
  EXPECT_EQ(seamless::png_info(png).width, 100000);
}
