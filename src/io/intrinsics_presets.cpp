#include "io/intrinsics_presets.hpp"

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
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

Intrinsics resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder) {
  Intrinsics K;
  if (p.preset == "custom") {
    K = make(p.fx, p.fy, p.cx, p.cy);
  } else if (p.preset == "auto") {
    namespace fs = std::filesystem;
    std::string name = folder.empty() ? "" : fs::path(folder).lexically_normal().filename().string();
    if (name.empty() && !folder.empty()) name = fs::path(folder).lexically_normal().parent_path().filename().string();
    if (!folder.empty() && fs::exists(fs::path(folder) / "calibration.txt"))
      return read_calibration((fs::path(folder) / "calibration.txt").string());
    const char* keys[3][2] = {{"freiburg1", "fr1"}, {"freiburg2", "fr2"}, {"freiburg3", "fr3"}};
    K = intrinsics_preset("kinect_v1");
    for (int i = 0; i < 3; ++i)
      if (name.find(keys[i][0]) != std::string::npos || name.find(keys[i][1]) != std::string::npos)
        K = intrinsics_preset(keys[i][0]);
  } else {
    K = intrinsics_preset(p.preset);
  }
  K.width = p.width;
  K.height = p.height;
  return K;
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
