// The libFuzzer targets' bodies (tests/fuzz/README.md), one function per target: fuzz_<name>.cpp
// hands libFuzzer's input to it, and fuzz_regressions_test runs it on every seed and on every input
// that once crashed (tests/fuzz/regressions/<name>/), in the normal and the sanitizer builds.
// A function returns normally when the reader accepted the input or rejected it with a
// seamless::Error; anything else (a crash, a sanitizer report, another exception, a broken
// property: fuzz::Violation) is a bug.
#pragma once
#include <cctype>

#include "config/config.hpp"
#include "fuzz_util.hpp"
#include "io/frame_folder_source.hpp"
#include "io/jpeg_io.hpp"
#include "io/ply.hpp"
#include "io/png_io.hpp"
#include "io/trajectory.hpp"
#include "io/tum_source.hpp"
#include "physics/builders.hpp"

namespace seamless::fuzz {

// The experiment loader (YAML text plus --set overrides). Input: YAML; every line that starts
// with "--set " is taken out as an override (KEY=VALUE). An experiment that loads must also survive
// its own round trip: its effective config (config.yaml of every run) parses back to the same
// experiment.
inline void config(const std::uint8_t* data, std::size_t size) {
  std::string_view in(reinterpret_cast<const char*>(data), size);
  std::string yaml;
  std::vector<std::string> sets;
  while (!in.empty()) {
    std::size_t end = in.find('\n');
    std::string_view line = in.substr(0, end);
    if (line.substr(0, 6) == "--set ") sets.emplace_back(line.substr(6));
    else yaml.append(line).append("\n");
    in.remove_prefix(end == std::string_view::npos ? in.size() : end + 1);
  }
  expect_error_or_success([&] {
    Experiment e = parse_experiment(yaml, sets, "fuzz.yaml");
    Experiment again = parse_experiment(to_yaml(e), {}, "effective.yaml");
    const std::vector<std::string> diff = diff_experiments(e, again);
    if (!diff.empty()) throw Violation("the effective config does not load back as the experiment: " + diff[0]);
  });
}

// A TUM RGB-D folder's text files. Input: rgb.txt, depth.txt, groundtruth.txt, accelerometer.txt,
// associations.txt and calibration.txt, separated by lines "--8<--" (an empty part: no file).
// TumSource reads them all (pairing, intrinsics, ground truth, accelerometer) without decoding an
// image; metadata() then looks up every pair's ground truth and accelerometer sample.
inline void tum(const std::uint8_t* data, std::size_t size) {
  static const char* names[] = {"rgb.txt",           "depth.txt",        "groundtruth.txt",
                                "accelerometer.txt", "associations.txt", "calibration.txt"};
  std::vector<std::string_view> p = parts(data, size, 6);
  const std::string dir = fresh_folder("tum");
  for (int i = 0; i < 6; ++i)
    if (!p[i].empty()) put("tum/" + std::string(names[i]), p[i]);
  InputParams params;
  params.source = InputSource::tum;
  params.path = dir;
  params.intrinsics.preset = "auto";  // calibration.txt when there is one
  expect_error_or_success([&] {
    TumSource src(params);
    for (std::size_t i = 0; i < src.pairs().size(); ++i) (void)src.metadata(i);
  });
  // The readers on their own, whatever the folder made of them.
  expect_error_or_success([&] { (void)read_tum_list(dir + "/rgb.txt"); });
  expect_error_or_success([&] {
    Trajectory t = read_tum_trajectory(dir + "/groundtruth.txt");
    if (!t.empty())
      for (double dt : {-1.0, 0.0, 0.005, 0.5}) (void)interpolate_pose(t, t.front().timestamp + dt);
  });
}

// A frame folder (7-Scenes / 3DMatch layout, src/io/frame_folder_source.hpp). Input, parts
// separated by lines "--8<--": file names (one a line; characters other than [A-Za-z0-9._-]
// dropped), then the content given to every *.pose.txt, to camera-intrinsics.txt and
// intrinsics.K.txt, to gravity-direction.txt, to every *.depth.png and to every *.color.*. The
// source lists the folder, reads poses, gravity and intrinsics, and decodes the first frames.
inline bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}
inline void frames(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string_view> p = parts(data, size, 6);
  const std::string dir = fresh_folder("frames");
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
    put("frames/" + name, content);
  }
  InputParams params;
  params.source = InputSource::frames;
  params.path = dir;
  expect_error_or_success([&] {
    FrameFolderSource src(params);
    RgbdFrame frame;
    for (int i = 0; i < 2 && src.next(frame); ++i) {
    }
  });
}

// PNG decoding (src/io/png_io.hpp) as depth (16-bit), mask (8-bit) and colour, and colour images
// told apart by content (read_colour_image).
inline void png(const std::uint8_t* data, std::size_t size) {
  const std::string path = put("in.png", {reinterpret_cast<const char*>(data), size});
  expect_error_or_success([&] { (void)png_info(path); });
  expect_error_or_success([&] { (void)read_png_u16(path); });
  expect_error_or_success([&] { (void)read_png_u8(path); });
  expect_error_or_success([&] { (void)read_png_rgb(path); });
  expect_error_or_success([&] { (void)read_colour_image(path); });
}

// JPEG decoding (src/io/jpeg_io.hpp) and colour images told apart by content.
inline void jpeg(const std::uint8_t* data, std::size_t size) {
  const std::string path = put("in.jpg", {reinterpret_cast<const char*>(data), size});
  expect_error_or_success([&] { (void)read_jpeg_rgb(path); });
  expect_error_or_success([&] { (void)image_format(path); });
  expect_error_or_success([&] { (void)read_colour_image(path); });
}

// The PLY mesh reader (src/io/ply.hpp: every encoding). A mesh that loads must be usable: every triangle's
// indices name one of its vertices.
inline void ply(const std::uint8_t* data, std::size_t size) {
  const std::string path = put("in.ply", {reinterpret_cast<const char*>(data), size});
  expect_error_or_success([&] {
    Mesh m = read_mesh_ply(path);
    const auto n = static_cast<int>(m.positions.size());
    for (const int3& t : m.triangles)
      if (t.x < 0 || t.y < 0 || t.z < 0 || t.x >= n || t.y >= n || t.z >= n)
        throw Violation("read_mesh_ply accepted a triangle with a vertex index out of range");
  });
}

// The OBJ reader of rigid mesh bodies (src/physics/builders.cpp), through voxelize_obj on a grid
// of at most 10 x 10 x 10 cells (the mesh is fitted into 0.5 m at 5 cm).
inline void obj(const std::uint8_t* data, std::size_t size) {
  const std::string path = put("in.obj", {reinterpret_cast<const char*>(data), size});
  expect_error_or_success([&] { (void)voxelize_obj(path, 0.05f, vec3{0.5f, 0.5f, 0.5f}); });
}

}  // namespace seamless::fuzz
