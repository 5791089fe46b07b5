#include "io/camera_file.hpp"

#include <yaml-cpp/yaml.h>

#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

#include "core/error.hpp"

namespace seamless {
namespace {

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw InputError("camera file '" + path + "': " + what);
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open camera file '" + path + "': " + std::strerror(errno));
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

double yaml_number(const YAML::Node& n, const std::string& key, const std::string& path) {
  if (!n.IsScalar()) fail(path, key + " is not a number");
  try {
    return n.as<double>();
  } catch (const YAML::Exception&) {
    fail(path, key + " is '" + n.Scalar() + "', not a number");
  }
}

// The first of `keys` that the map has (an undefined node when none).
YAML::Node first_of(const YAML::Node& root, std::initializer_list<const char*> keys, std::string* found = nullptr) {
  for (const char* k : keys)
    if (const YAML::Node n = root[k]; n.IsDefined() && !n.IsNull()) {
      if (found) *found = k;
      return n;
    }
  return YAML::Node(YAML::NodeType::Undefined);
}

// The numbers of a matrix node: a plain sequence (ROS camera_info's K, D) or a map with rows, cols
// and data (OpenCV's !!opencv-matrix, ROS camera_calibration_parsers' camera_matrix).
std::vector<double> yaml_matrix(const YAML::Node& n, const std::string& key, const std::string& path) {
  // (Not `data = n["data"]` on a copy of n: yaml-cpp's assignment would overwrite n itself.)
  const YAML::Node data = n.IsMap() ? n["data"] : n;
  if (n.IsMap() && !data.IsDefined()) fail(path, key + " has no data (expected rows, cols and data)");
  if (!data.IsSequence()) fail(path, key + " is not a list of numbers (or a matrix with rows, cols and data)");
  std::vector<double> v;
  for (std::size_t i = 0; i < data.size(); ++i)
    v.push_back(yaml_number(data[i], key + "[" + std::to_string(i) + "]", path));
  if (n.IsMap() && n["rows"].IsDefined() && n["cols"].IsDefined()) {
    const double rows = yaml_number(n["rows"], key + ".rows", path), cols = yaml_number(n["cols"], key + ".cols", path);
    if (rows * cols != static_cast<double>(v.size()))
      fail(path, key + " says " + n["rows"].Scalar() + "x" + n["cols"].Scalar() + " but holds " +
                     std::to_string(v.size()) + " numbers");
  }
  return v;
}

Intrinsics from_row_major(const std::vector<double>& v, const std::string& key, const std::string& path) {
  if (v.size() != 9)
    fail(path, key + " holds " + std::to_string(v.size()) + " numbers; expected the 3x3 camera matrix, nine numbers");
  double k[9];
  for (int i = 0; i < 9; ++i) k[i] = v[i];
  return intrinsics_from_matrix(k, "camera file '" + path + "', " + key);
}

// OpenCV's radial-tangential model in its order k1 k2 p1 p2 k3; longer lists (rational_polynomial's
// k4 k5 k6, thin prism, tilt) are accepted only when the extra terms are zero.
void set_distortion(Intrinsics& K, const std::vector<double>& d, const std::string& key, const std::string& path) {
  for (std::size_t i = 0; i < d.size(); ++i) {
    if (i < 5) K.dist[i] = static_cast<float>(d[i]);
    else if (d[i] != 0)
      fail(path,
           key + " has " + std::to_string(d.size()) + " coefficients and coefficient " + std::to_string(i + 1) +
               " is not zero: only k1 k2 p1 p2 k3 (OpenCV's radial-tangential model, ROS plumb_bob) are supported");
  }
}

void set_size(CameraFile& c, const YAML::Node& root, std::initializer_list<const char*> w,
              std::initializer_list<const char*> h, const std::string& path) {
  std::string wk, hk;
  const YAML::Node wn = first_of(root, w, &wk), hn = first_of(root, h, &hk);
  if (!wn.IsDefined() || !hn.IsDefined()) return;
  const double width = yaml_number(wn, wk, path), height = yaml_number(hn, hk, path);
  if (width == 0 && height == 0) return;  // an unset CameraInfo
  if (!(width >= 1 && height >= 1 && width <= 16384 && height <= 16384 && width == std::floor(width) &&
        height == std::floor(height)))
    fail(path, "image size " + wn.Scalar() + "x" + hn.Scalar() + " is not a size in pixels");
  c.K.width = static_cast<int>(width), c.K.height = static_cast<int>(height);
  c.has_size = true;
}

CameraFile read_orbslam(const YAML::Node& root, const std::string& prefix, const std::string& path) {
  CameraFile c;
  c.format = "ORB-SLAM YAML";
  if (const YAML::Node t = first_of(root, {"Camera.type"}); t.IsDefined() && t.Scalar() != "PinHole")
    fail(path, "Camera.type is '" + t.Scalar() + "'; only PinHole cameras are supported");
  auto get = [&](const char* name, bool required) -> double {
    const YAML::Node n = root[prefix + name];
    if (!n.IsDefined()) {
      if (required)
        fail(path, "has " + prefix + "fx but no " + prefix + name + " (ORB-SLAM layout: " + prefix +
                       "fx, fy, cx, cy, optional k1 k2 p1 p2 k3)");
      return 0;
    }
    return yaml_number(n, prefix + name, path);
  };
  const double k[9] = {get("fx", true), 0, get("cx", true), 0, get("fy", true), get("cy", true), 0, 0, 1};
  c.K = intrinsics_from_matrix(k, "camera file '" + path + "'");
  set_distortion(c.K, {get("k1", false), get("k2", false), get("p1", false), get("p2", false), get("k3", false)},
                 prefix + "k1..k3", path);
  set_size(c, root, {"Camera.width", "Camera1.width"}, {"Camera.height", "Camera1.height"}, path);
  return c;
}

CameraFile read_calibration_yaml(const YAML::Node& root, const std::string& path) {
  CameraFile c;
  c.format = "OpenCV/ROS calibration YAML";
  c.K = from_row_major(yaml_matrix(root["camera_matrix"], "camera_matrix", path), "camera_matrix", path);
  if (const YAML::Node m = root["distortion_model"];
      m.IsDefined() && m.Scalar() != "plumb_bob" && m.Scalar() != "rational_polynomial")
    fail(path, "distortion_model is '" + m.Scalar() + "'; only plumb_bob (OpenCV's radial-tangential) is supported");
  if (const YAML::Node d = root["distortion_coefficients"]; d.IsDefined())
    set_distortion(c.K, yaml_matrix(d, "distortion_coefficients", path), "distortion_coefficients", path);
  set_size(c, root, {"image_width"}, {"image_height"}, path);
  return c;
}

CameraFile read_camera_info(const YAML::Node& root, const std::string& key, const std::string& path) {
  CameraFile c;
  c.format = "ROS camera_info YAML";
  c.K = from_row_major(yaml_matrix(root[key], key, path), key, path);
  if (const YAML::Node m = first_of(root, {"distortion_model"});
      m.IsDefined() && !m.Scalar().empty() && m.Scalar() != "plumb_bob" && m.Scalar() != "rational_polynomial")
    fail(path, "distortion_model is '" + m.Scalar() + "'; only plumb_bob (OpenCV's radial-tangential) is supported");
  std::string dk;
  if (const YAML::Node d = first_of(root, {"D", "d"}, &dk); d.IsDefined())
    set_distortion(c.K, yaml_matrix(d, dk, path), dk, path);
  set_size(c, root, {"width"}, {"height"}, path);
  return c;
}

CameraFile read_yaml(std::string text, const std::string& path) {
  // cv::FileStorage starts its files with "%YAML:1.0", which is not a YAML 1.2 directive.
  if (text.rfind("%YAML", 0) == 0) text.erase(0, text.find('\n') == std::string::npos ? text.size() : text.find('\n'));
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    fail(path, "not YAML or JSON (line " + std::to_string(e.mark.line + 1) + ": " + e.msg + ")");
  }
  if (!root.IsMap()) fail(path, "is not a YAML map of keys");
  for (const char* prefix : {"Camera.", "Camera1."})
    if (root[std::string(prefix) + "fx"].IsDefined()) return read_orbslam(root, prefix, path);
  if (root["camera_matrix"].IsDefined()) return read_calibration_yaml(root, path);
  for (const char* key : {"K", "k"})
    if (root[key].IsDefined()) return read_camera_info(root, key, path);
  fail(path,
       "no camera found: expected Camera.fx ... (ORB-SLAM), camera_matrix (OpenCV or ROS calibration YAML), "
       "K (ROS camera_info) or, in JSON, intrinsic_matrix (Open3D)");
}

CameraFile read_open3d(const std::string& text, const std::string& path) {
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    fail(path, std::string("not valid JSON: ") + e.what());
  }
  if (!j.is_object() || !j.contains("intrinsic_matrix"))
    fail(path,
         "a JSON file without intrinsic_matrix (expected Open3D's PinholeCameraIntrinsic: width, height, "
         "intrinsic_matrix)");
  const nlohmann::json& m = j["intrinsic_matrix"];
  if (!m.is_array() || m.size() != 9)
    fail(path, "intrinsic_matrix is not a list of nine numbers (the 3x3 camera matrix, column-major)");
  double k[9];
  for (int col = 0; col < 3; ++col)
    for (int row = 0; row < 3; ++row) {
      const nlohmann::json& x = m[static_cast<std::size_t>(col * 3 + row)];
      if (!x.is_number()) fail(path, "intrinsic_matrix[" + std::to_string(col * 3 + row) + "] is not a number");
      k[row * 3 + col] = x.get<double>();  // Open3D stores the matrix column by column
    }
  CameraFile c;
  c.format = "Open3D JSON";
  c.K = intrinsics_from_matrix(k, "camera file '" + path + "', intrinsic_matrix (column-major)");
  for (const char* key : {"width", "height"})
    if (!j.contains(key) || !j[key].is_number_integer() || j[key].get<long long>() < 1 ||
        j[key].get<long long>() > 16384)
      fail(path, std::string("has no ") + key + " in pixels (Open3D's PinholeCameraIntrinsic has width and height)");
  c.K.width = j["width"].get<int>(), c.K.height = j["height"].get<int>();
  c.has_size = true;
  return c;
}

}  // namespace

Intrinsics intrinsics_from_matrix(const double (&k)[9], const std::string& where) {
  auto bad = [&](const std::string& what) {
    return InputError(where + ": " + what + "; expected K = [fx 0 cx; 0 fy cy; 0 0 1]");
  };
  if (k[6] != 0 || k[7] != 0 || k[8] != 1)
    throw bad("the bottom row is not 0 0 1 (a transposed or projection matrix?)");
  if (k[3] != 0) throw bad("the second row starts with " + std::to_string(k[3]) + ", not 0");
  // Below one pixel a focal length is no camera (and 0 cannot be divided by).
  if (!(std::abs(k[0]) >= 1 && std::abs(k[4]) >= 1)) throw bad("a focal length fx or fy is zero or below one pixel");
  // A skew below 1e-3 px changes no projection by a thousandth of a pixel across a 640-pixel image.
  if (std::abs(k[1]) > 1e-3) throw bad("a skew of " + std::to_string(k[1]) + " px, which the pinhole model here lacks");
  Intrinsics K;
  K.fx = static_cast<float>(k[0]), K.fy = static_cast<float>(k[4]);
  K.cx = static_cast<float>(k[2]), K.cy = static_cast<float>(k[5]);
  return K;
}

CameraFile read_camera_file(const std::string& path) {
  const std::string text = read_text(path);
  const std::size_t first = text.find_first_not_of(" \t\r\n\xef\xbb\xbf");
  if (first == std::string::npos) fail(path, "is empty");
  return text[first] == '{' ? read_open3d(text, path) : read_yaml(text, path);
}

}  // namespace seamless
