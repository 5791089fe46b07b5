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
#include "io/camera_file.hpp"
#include "io/input_params.hpp"
#include "io/number_file.hpp"

namespace seamless {
namespace fs = std::filesystem;
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

// A negative focal length as a flip of that image axis (IntrinsicsChoice's comment derives it).
void flip_negative_focal_lengths(IntrinsicsChoice& c) {
  Intrinsics& K = c.K;
  if (K.fx < 0) K.fx = -K.fx, K.cx = static_cast<float>(K.width - 1) - K.cx, c.flip_x = true;
  if (K.fy < 0) K.fy = -K.fy, K.cy = static_cast<float>(K.height - 1) - K.cy, c.flip_y = true;
}

}  // namespace

// Values published with the TUM RGB-D benchmark (vision.in.tum.de/data/datasets/rgbd-dataset/
// file_formats, "Intrinsic Camera Calibration of the Kinect"); fr3 images are already undistorted.
// kinect_v1 is the ROS/OpenNI default the same page gives for uncalibrated Kinects.
Intrinsics intrinsics_preset(const std::string& name) {
  if (name == "freiburg1") return make(517.3f, 516.5f, 318.6f, 255.3f, {0.2624f, -0.9531f, -0.0054f, 0.0026f, 1.1633f});
  if (name == "freiburg2")
    return make(520.9f, 521.0f, 325.1f, 249.7f, {0.2312f, -0.7849f, -0.0033f, -0.0001f, 0.9172f});
  if (name == "freiburg3") return make(535.4f, 539.2f, 320.1f, 247.6f);
  if (name == "kinect_v1") return make(525.f, 525.f, 319.5f, 239.5f);
  // The Asus Xtion of the Bonn RGB-D Dynamic dataset (Palazzolo et al., IROS 2019), as the dataset
  // publishes it (k1 k2 p1 p2 k3, OpenCV order); its images are stored as recorded, not undistorted.
  if (name == "bonn")
    return make(542.822841f, 542.576870f, 315.593520f, 237.756098f,
                {0.039903f, -0.099343f, -0.000730f, -0.000144f, 0.f});
  throw ConfigError("unknown intrinsics preset '" + name +
                    "': use freiburg1, freiburg2, freiburg3, kinect_v1, bonn, custom or auto");
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
    // The Bonn RGB-D Dynamic dataset's folders are rgbd_bonn_<scene>.
    if (s.compare(i, 4, "bonn") == 0 && (i + 4 == s.size() || !alpha(s[i + 4]))) {
      if (!found.empty() && found != "bonn") return "";
      found = "bonn";
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
  IntrinsicsChoice c;
  if (!p.file.empty()) {
    if (p.preset != "auto")
      throw ConfigError("input.intrinsics.file '" + p.file + "' and input.intrinsics.preset " + p.preset +
                        " both name the camera: keep one (preset auto with the file)");
    const CameraFile f = read_camera_file(p.file);
    c.K = f.K;
    c.chosen = fs::path(p.file).filename().string();
    c.reason = "input.intrinsics.file: " + p.file + " (" + f.format + ")";
    if (!f.has_size) c.K.width = p.width, c.K.height = p.height;
    flip_negative_focal_lengths(c);
    return c;
  }
  if (p.preset == "custom") {
    if (!(std::abs(p.fx) >= 1 && std::abs(p.fy) >= 1))
      throw ConfigError("input.intrinsics.fx and fy must be at least one pixel in size (negative: a flipped axis)");
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
      flip_negative_focal_lengths(c);
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
                 "' names no known camera (fr1/fr2/fr3, freiburg1/2/3, bonn) and the folder has no calibration.txt, "
                 "camera-intrinsics.txt or intrinsics.K.txt";
    }
  }
  c.K.width = p.width;
  c.K.height = p.height;
  flip_negative_focal_lengths(c);
  return c;
}

IntrinsicsChoice resolve_intrinsics(const IntrinsicsParams& p, const std::string& folder) {
  IntrinsicsChoice c = choose_intrinsics(p, folder);
  if (c.flip_x || c.flip_y)
    spdlog::info(
        "intrinsics: {} has a negative focal length {}: every image is read with its {} flipped, which "
        "makes it an ordinary pinhole seeing the same 3D points (fx fy cx cy below are the flipped image's)",
        c.chosen, c.flip_y ? "fy" : "fx", c.flip_x && c.flip_y ? "columns and rows" : (c.flip_y ? "rows" : "columns"));
  if (c.generic)
    spdlog::warn(
        "intrinsics: {}: USING THE GENERIC KINECT v1 SET ({}), which can be off by several pixels for "
        "this camera; set input.intrinsics.preset (freiburg1, freiburg2, freiburg3, kinect_v1, bonn or custom "
        "with fx fy cx cy) or put a calibration.txt in the folder",
        c.reason, describe_intrinsics(c.K));
  else if (!folder.empty() || p.preset != "auto" || !p.file.empty())
    spdlog::info("intrinsics: {} ({}): {}", c.chosen, c.reason, describe_intrinsics(c.K));
  return c;
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
  const std::vector<double> v = read_numbers(path, "camera matrix file", "(expected a 3x3 matrix K, nine numbers)");
  if (v.size() != 9)
    throw InputError("camera matrix file '" + path + "' holds " + std::to_string(v.size()) +
                     " numbers; expected a 3x3 matrix K = [fx 0 cx; 0 fy cy; 0 0 1], nine numbers");
  double k[9];
  std::copy(v.begin(), v.end(), k);
  return intrinsics_from_matrix(k, "camera matrix file '" + path + "'");
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
    throw InputError("malformed calibration file '" + path +
                     "': expected 'fx fy cx cy width height d0 d1 d2 d3 d4', got '" + line + "'");
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
