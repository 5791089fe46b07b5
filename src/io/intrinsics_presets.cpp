#include "io/intrinsics_presets.hpp"

#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/error.hpp"
#include "core/log.hpp"
#include "io/number_file.hpp"
#include "io/input_params.hpp"

namespace seamless {
namespace {

Intrinsics make(float fx, float fy, float cx, float cy, std::initializer_list<float> d = {}) {
  Intrinsics K;
  K.fx = fx;
  K.fy = fy;
  K.cx = cx;
  K.cy = cy;
  int i = 0;
  for (float v : d) K.dist[i++] = v;
  return K;
}

}  // namespace

// Values published with the TUM RGB-D benchmark (vision.in.tum.de/data/datasets/rgbd-dataset/
// file_formats, "Intrinsic Camera Calibration of the Kinect"); fr3 images are already undistorted.
// kinect_v1 is the ROS/OpenNI default the same page gives for uncalibrated Kinects.
Intrinsics intrinsics_preset(const std::string& name) {
  if (name == "freiburg1") return make(517.3f, 516.5f, 318.6f, 255.3f, {0.2624f, -0.9531f, -0.0054f, 0.0026f, 1.1633f});
  if (name == "freiburg2") return make(520.9f, 521.0f, 325.1f, 249.7f, {0.2312f, -0.7849f, -0.0033f, -0.0001f, 0.9172f});
  if (name == "freiburg3") return make(535.4f, 539.2f, 320.1f, 247.6f);
  if (name == "kinect_v1") return make(525.f, 525.f, 319.5f, 239.5f);
  throw ConfigError("unknown intrinsics preset '" + name + "': use freiburg1, freiburg2, freiburg3, kinect_v1, custom or auto");
}

Intrinsics resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder, std::string* origin) {
  Intrinsics K;
  std::string from;
  if (p.preset == "custom") {
    K = make(p.fx, p.fy, p.cx, p.cy);
    from = "input.intrinsics (custom)";
  } else if (p.preset == "auto") {
    namespace fs = std::filesystem;
    std::string name = folder.empty() ? "" : fs::path(folder).lexically_normal().filename().string();
    if (name.empty() && !folder.empty()) name = fs::path(folder).lexically_normal().parent_path().filename().string();
    if (!folder.empty() && fs::exists(fs::path(folder) / "calibration.txt")) {
      const std::string file = (fs::path(folder) / "calibration.txt").string();
      if (origin) *origin = "file '" + file + "' (preset auto)";
      return read_calibration(file);
    }
    const std::string matrix = folder.empty() ? "" : find_intrinsics_matrix(folder);
    const char* keys[3][2] = {{"freiburg1", "fr1"}, {"freiburg2", "fr2"}, {"freiburg3", "fr3"}};
    K = intrinsics_preset("kinect_v1");
    from = "preset kinect_v1 (auto: no calibration file, no freiburg name)";
    if (!matrix.empty()) {
      K = read_intrinsics_matrix(matrix);
      from = "file '" + matrix + "' (preset auto)";
    } else {
      for (int i = 0; i < 3; ++i)
        if (name.find(keys[i][0]) != std::string::npos || name.find(keys[i][1]) != std::string::npos) {
          K = intrinsics_preset(keys[i][0]);
          from = std::string("preset ") + keys[i][0] + " (auto: from the folder's name)";
        }
    }
  } else {
    K = intrinsics_preset(p.preset);
    from = "preset " + p.preset;
  }
  K.width = p.width;
  K.height = p.height;
  if (origin) *origin = from;
  return K;
}

std::string find_intrinsics_matrix(const std::string& folder) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::path(folder);
  fs::path abs = fs::absolute(dir).lexically_normal();
  if (!abs.has_filename()) abs = abs.parent_path();  // "seq-01/" names the folder seq-01
  const fs::path parent = abs.parent_path();
  for (const fs::path& d : {dir, parent})
    for (const char* name : kIntrinsicsMatrixFiles)
      if (!d.empty() && fs::is_regular_file(d / name)) return (d / name).string();
  return "";
}

Intrinsics read_intrinsics_matrix(const std::string& path) {
  const std::vector<double> v =
      read_numbers(path, "camera matrix file", "(expected a 3x3 matrix K, nine numbers)");
  if (v.size() != 9)
    throw InputError("camera matrix file '" + path + "' holds " + std::to_string(v.size()) +
                " numbers; expected a 3x3 matrix K = [fx 0 cx; 0 fy cy; 0 0 1], nine numbers");
  auto bad = [&](const std::string& what) {
    return Error("camera matrix file '" + path + "': " + what + "; expected K = [fx 0 cx; 0 fy cy; 0 0 1]");
  };
  if (v[6] != 0 || v[7] != 0 || v[8] != 1) throw bad("the bottom row is not 0 0 1 (a transposed or projection matrix?)");
  if (v[3] != 0) throw bad("the second row starts with " + std::to_string(v[3]) + ", not 0");
  if (!(v[0] > 0 && v[4] > 0)) throw bad("the focal lengths fx, fy must be positive");
  // A skew below 1e-3 px changes no projection by a thousandth of a pixel across a 640-pixel image.
  if (std::abs(v[1]) > 1e-3) throw bad("a skew of " + std::to_string(v[1]) + " px, which the pinhole model here lacks");
  return make(static_cast<float>(v[0]), static_cast<float>(v[4]), static_cast<float>(v[2]), static_cast<float>(v[5]));
}

void log_intrinsics(const std::string& what, const Intrinsics& K, const std::string& origin) {
  spdlog::info("{}: intrinsics fx {} fy {} cx {} cy {}, {}x{}, distortion {} {} {} {} {}, from {}", what, K.fx, K.fy,
               K.cx, K.cy, K.width, K.height, K.dist[0], K.dist[1], K.dist[2], K.dist[3], K.dist[4], origin);
}

Intrinsics read_calibration(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open calibration file '" + path + "': " + std::strerror(errno));
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream ss(line);
    Intrinsics K;
    if (ss >> K.fx >> K.fy >> K.cx >> K.cy >> K.width >> K.height >> K.dist[0] >> K.dist[1] >> K.dist[2] >> K.dist[3] >>
        K.dist[4])
      return K;
    throw InputError("malformed calibration file '" + path + "': expected 'fx fy cx cy width height d0 d1 d2 d3 d4', got '" +
                line + "'");
  }
  throw InputError("calibration file '" + path + "' has no calibration line");
}

void write_calibration(const std::string& path, const Intrinsics& K) {
  std::ofstream out(path);
  out << "# fx fy cx cy width height d0 d1 d2 d3 d4 (pinhole + Brown-Conrady, OpenCV order)\n";
  out.precision(9);
  out << K.fx << ' ' << K.fy << ' ' << K.cx << ' ' << K.cy << ' ' << K.width << ' ' << K.height;
  for (float d : K.dist) out << ' ' << d;
  out << '\n';
  if (!out) throw Error("cannot write calibration file '" + path + "'");
}

}  // namespace seamless
