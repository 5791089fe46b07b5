// libFuzzer target: a frame folder (7-Scenes / 3DMatch layout, src/io/frame_folder_source.hpp).
// Input, parts separated by lines "--8<--": file names (one a line; characters other than
// [A-Za-z0-9._-] dropped), then the content given to every *.pose.txt, to camera-intrinsics.txt
// and intrinsics.K.txt, to gravity-direction.txt, to every *.depth.png and to every *.color.*.
// The source lists the folder, reads poses, gravity and intrinsics, and decodes the first frames.
#include "fuzz_util.hpp"
#include "io/frame_folder_source.hpp"

namespace {
bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  std::vector<std::string_view> p = fuzz::parts(data, size, 6);
  const std::string dir = fuzz::fresh_folder("frames");
  std::string_view names = p[0];
  for (int count = 0; !names.empty() && count < 64; ++count) {
    std::size_t end = names.find('\n');
    std::string name;
    for (char c : names.substr(0, end))
      if (std::isalnum(static_cast<unsigned char>(c)) || c == '.' || c == '_' || c == '-') name += c;
    names.remove_prefix(end == std::string_view::npos ? names.size() : end + 1);
    if (name.empty() || name[0] == '.' || name.size() > 100) continue;
    std::string_view content;
    if (ends_with(name, ".pose.txt")) content = p[1];
    else if (name == "camera-intrinsics.txt" || name == "intrinsics.K.txt") content = p[2];
    else if (name == "gravity-direction.txt") content = p[3];
    else if (ends_with(name, ".depth.png")) content = p[4];
    else if (name.find(".color.") != std::string::npos) content = p[5];
    fuzz::put("frames/" + name, content);
  }
  InputParams params;
  params.source = "frames";
  params.path = dir;
  fuzz::expect_error_or_success([&] {
    FrameFolderSource src(params);
    RgbdFrame frame;
    for (int i = 0; i < 2 && src.next(frame); ++i) {
    }
  });
  return 0;
}
