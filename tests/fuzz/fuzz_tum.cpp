// libFuzzer target: a TUM RGB-D folder's text files. Input: rgb.txt, depth.txt, groundtruth.txt,
// accelerometer.txt and associations.txt, separated by lines "--8<--" (an empty part: no file).
// TumSource reads them all (pairing, ground truth, accelerometer) without decoding an image;
// metadata() then looks up every pair's ground truth and accelerometer sample.
#include "fuzz_util.hpp"
#include "io/trajectory.hpp"
#include "io/tum_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace seamless;
  static const char* names[] = {"rgb.txt", "depth.txt", "groundtruth.txt", "accelerometer.txt", "associations.txt"};
  std::vector<std::string_view> p = fuzz::parts(data, size, 5);
  const std::string dir = fuzz::fresh_folder("tum");
  for (int i = 0; i < 5; ++i)
    if (!p[i].empty()) fuzz::put("tum/" + std::string(names[i]), p[i]);
  InputParams params;
  params.source = "tum";
  params.path = dir;
  params.intrinsics.preset = "freiburg1";
  fuzz::expect_error_or_success([&] {
    TumSource src(params);
    for (std::size_t i = 0; i < src.pairs().size(); ++i) (void)src.metadata(i);
  });
  // The readers on their own, whatever the folder made of them.
  fuzz::expect_error_or_success([&] { (void)read_tum_list(dir + "/rgb.txt"); });
  fuzz::expect_error_or_success([&] {
    Trajectory t = read_tum_trajectory(dir + "/groundtruth.txt");
    if (!t.empty())
      for (double dt : {-1.0, 0.0, 0.005, 0.5})
        (void)interpolate_pose(t, t.front().timestamp + dt);
  });
  return 0;
}
