#include "io/intrinsics_presets.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include <spdlog/spdlog.h>

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

std::string camera_in_folder_name(const std::string& name) {
  std::string s(name.size(), ' ');
  std::transform(name.begin(), name.end(), s.begin(), [](unsigned char c) { return std::tolower(c); });
  auto alpha = [](char c) { return c >= 'a' && c <= 'z'; };
  auto digit = [](char c) { return c >= '0' && c <= '9'; };
  std::string found;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (i > 0 && alpha(s[i - 1])) continue;  // "fr" must start a word: not the end of "buffr1"
    for (std::string key : {"freiburg", "fr"}) {
      if (s.compare(i, key.size(), key) != 0) continue;
      std::size_t j = i + key.size();
      if (j < s.size() && (s[j] == '_' || s[j] == '-')) ++j;
      if (j >= s.size() || s[j] < '1' || s[j] > '3' || (j + 1 < s.size() && digit(s[j + 1]))) continue;
      std::string camera = std::string("freiburg") + s[j];
      if (!found.empty() && found != camera) return "";  // names two cameras: cannot tell
      found = camera;
    }
  }
  return found;
}

std::string describe_intrinsics(const Intrinsics& K) {
  std::ostringstream s;
  s.precision(7);
  s << "fx " << K.fx << " fy " << K.fy << " cx " << K.cx << " cy " << K.cy << ", " << K.width << "x" << K.height
    << ", distortion";
  bool any = false;
  for (float d : K.dist) any = any || d != 0.f;
  if (!any) return s.str() + " none";
  for (float d : K.dist) s << ' ' << d;
  return s.str();
}

IntrinsicsChoice choose_intrinsics(const IntrinsicsParams& p, const std::string& folder) {
  namespace fs = std::filesystem;
  IntrinsicsChoice c;
  if (p.preset == "custom") {
    c.K = make(p.fx, p.fy, p.cx, p.cy);
    c.chosen = "custom";
    c.reason = "input.intrinsics.preset: custom (fx fy cx cy from the config)";
  } else if (p.preset != "auto") {
    c.K = intrinsics_preset(p.preset);
    c.chosen = p.preset;
    c.reason = "input.intrinsics.preset: " + p.preset;
  } else if (folder.empty()) {
    // The synthetic room renders with these intrinsics and a live Kinect v1 without a calibration
    // delivers about them: for these sources the generic set is the right one, not a guess.
    c.K = intrinsics_preset("kinect_v1");
    c.chosen = "kinect_v1";
    c.reason = "preset auto for a source without a folder";
  } else {
    fs::path dir = fs::path(folder).lexically_normal();
    std::string name = dir.filename().string();
    if (name.empty()) name = dir.parent_path().filename().string();  // "a/b/" names b
    const fs::path calibration = fs::path(folder) / "calibration.txt";
    const std::string named = camera_in_folder_name(name);
    const std::string matrix = find_intrinsics_matrix(folder);
    if (fs::exists(calibration)) {
      c.K = read_calibration(calibration.string());
      c.chosen = "calibration.txt";
      c.reason = "preset auto: the folder has " + calibration.string();
      return c;  // its width and height are the recording's
    } else if (!matrix.empty()) {
      c.K = read_intrinsics_matrix(matrix);
      c.chosen = fs::path(matrix).filename().string();
      c.reason = "preset auto: the camera matrix in " + matrix;
    } else if (!named.empty()) {
      c.chosen = named;
      c.K = intrinsics_preset(c.chosen);
      c.reason = "preset auto: the folder name '" + name + "' names " + c.chosen;
    } else {
      c.K = intrinsics_preset("kinect_v1");
      c.chosen = "kinect_v1";
      c.generic = true;
      c.reason = "preset auto: the folder name '" + name +
                 "' names no TUM camera (fr1/fr2/fr3, freiburg1/2/3) and the folder has no calibration.txt, "
                 "camera-intrinsics.txt or intrinsics.K.txt";
    }
  }
  c.K.width = p.width;
  c.K.height = p.height;
  return c;
}

Intrinsics resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder) {
  IntrinsicsChoice c = choose_intrinsics(p, folder);
  if (c.generic)
    spdlog::warn("intrinsics: {}: USING THE GENERIC KINECT v1 SET ({}), which can be off by several pixels for "
                 "this camera; set input.intrinsics.preset (freiburg1, freiburg2, freiburg3, kinect_v1 or custom "
                 "with fx fy cx cy) or put a calibration.txt in the folder",
                 c.reason, describe_intrinsics(c.K));
  else if (!folder.empty() || p.preset != "auto")
    spdlog::info("intrinsics: {} ({}): {}", c.chosen, c.reason, describe_intrinsics(c.K));
  return c.K;
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
