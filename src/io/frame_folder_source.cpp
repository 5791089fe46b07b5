#include "io/frame_folder_source.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "core/error.hpp"
#include "core/log.hpp"
#include "io/depth_scale.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/jpeg_io.hpp"
#include "io/number_file.hpp"
#include "io/png_io.hpp"
#include "io/rgbd_pair.hpp"

namespace seamless {
namespace fs = std::filesystem;
namespace {

// Standard gravity: the specific force an accelerometer at rest reads, m/s^2.
constexpr float kStandardGravity = 9.80665f;

// `name` in the folder, else in its parent (7-Scenes and 3DMatch keep one file per scene, above its
// sequence folders); "" when neither has it.
std::string find_here_or_above(const std::string& folder, const char* name) {
  fs::path abs = fs::absolute(fs::path(folder)).lexically_normal();
  if (!abs.has_filename()) abs = abs.parent_path();
  for (const fs::path& d : {fs::path(folder), abs.parent_path()})
    if (!d.empty() && fs::is_regular_file(d / name)) return (d / name).string();
  return "";
}

// "frame-000015.color.png" -> 15 and "color.png"; false for another name.
bool parse_frame_name(const std::string& name, std::int64_t& number, std::string& kind) {
  const std::string prefix = "frame-";
  if (name.compare(0, prefix.size(), prefix) != 0) return false;
  std::size_t i = prefix.size(), digits = 0;
  while (i + digits < name.size() && std::isdigit(static_cast<unsigned char>(name[i + digits]))) ++digits;
  if (digits == 0 || digits > 12 || i + digits >= name.size() || name[i + digits] != '.') return false;
  number = std::stoll(name.substr(i, digits));
  kind = name.substr(i + digits + 1);
  return true;
}

std::string frame_name(std::int64_t number) {
  char b[32];
  std::snprintf(b, sizeof b, "frame-%06lld", static_cast<long long>(number));
  return b;
}

}  // namespace

std::vector<FrameFolderEntry> list_frame_folder(const std::string& folder) {
  if (!fs::is_directory(folder))
    throw InputError("input.path '" + folder +
                     "' is not a folder (source: frames wants a folder of frame-NNNNNN.color.png, "
                     ".depth.png and .pose.txt files)");
  std::map<std::int64_t, FrameFolderEntry> by_number;
  for (const fs::directory_entry& e : fs::directory_iterator(folder)) {
    const std::string name = e.path().filename().string();
    std::int64_t number = 0;
    std::string kind;
    if (!parse_frame_name(name, number, kind)) continue;
    const bool colour = kind == "color.png" || kind == "color.jpg" || kind == "color.jpeg";
    if (!colour && kind != "depth.png" && kind != "pose.txt") continue;  // frame-N.something else: not ours
    FrameFolderEntry& f = by_number[number];
    f.number = number;
    if (colour) {
      if (!f.colour.empty())
        throw InputError("frame folder '" + folder + "' has two colour images for frame " + std::to_string(number) +
                         ": '" + f.colour + "' and '" + name + "'; keep one");
      f.colour = name;
    } else {
      (kind == "depth.png" ? f.depth : f.pose) = name;
    }
  }
  std::vector<FrameFolderEntry> out;
  for (auto& [n, f] : by_number) out.push_back(f);
  return out;
}

std::optional<SE3> read_pose_matrix(const std::string& path) {
  std::vector<double> v = read_numbers(path, "pose file");
  if (v.size() != 16)
    throw InputError("pose file '" + path + "' holds " + std::to_string(v.size()) +
                     " numbers; expected a 4x4 camera-to-world matrix, 16 numbers row by row");
  for (double x : v)
    if (!std::isfinite(x)) return std::nullopt;  // the capture marks a lost pose this way
  // Exact comparison: every writer of these files prints the constant row as 0 0 0 1.
  if (v[12] != 0 || v[13] != 0 || v[14] != 0 || v[15] != 1)
    throw InputError(
        "pose file '" + path + "': the bottom row is " + std::to_string(v[12]) + " " + std::to_string(v[13]) + " " +
        std::to_string(v[14]) + " " + std::to_string(v[15]) +
        ", not 0 0 0 1 (a transposed matrix, translation in the last row?); expected a 4x4 camera-to-world "
        "matrix row by row");
  Eigen::Matrix3d R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) R(r, c) = v[4 * r + c];
  // Rotations stored with 6-7 significant digits are orthonormal to ~1e-6; 1e-2 (0.6 degrees of
  // shear) separates drift from a matrix that is not a rotation at all (scaled, sheared, a K).
  const double off = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (off > 1e-2 || R.determinant() < 0)
    throw InputError("pose file '" + path + "': the upper-left 3x3 is not a rotation (R^T R differs from I by " +
                     std::to_string(off) + ", det " + std::to_string(R.determinant()) +
                     "); expected a rigid camera-to-world matrix");
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Matrix3d Rn = svd.matrixU() * svd.matrixV().transpose();  // det +1: checked above
  SE3 T;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.R.m[r][c] = static_cast<float>(Rn(r, c));
  }
  T.t = {static_cast<float>(v[3]), static_cast<float>(v[7]), static_cast<float>(v[11])};
  return T;
}

vec3 read_gravity_direction(const std::string& path) {
  std::vector<double> v = read_numbers(path, "gravity file");
  if (v.size() != 3)
    throw InputError("gravity file '" + path + "' holds " + std::to_string(v.size()) +
                     " numbers; expected the direction of gravity in the poses' world frame, three numbers");
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  if (!(n > 1e-6) || !std::isfinite(n))
    throw InputError("gravity file '" + path +
                     "' holds a zero or non-finite vector; expected the direction of gravity");
  return {static_cast<float>(v[0] / n), static_cast<float>(v[1] / n), static_cast<float>(v[2] / n)};
}

FrameFolderSource::FrameFolderSource(const InputParams& params, bool pinned)
    : params_(params), folder_(params.path), scale_(effective_depth_scale(params)), pinned_(pinned) {
  if (folder_.empty()) throw InputError("input.path is empty: set it to a frame folder (source: frames)");
  std::vector<FrameFolderEntry> all = list_frame_folder(folder_);
  for (const FrameFolderEntry& f : all) {
    if (!f.colour.empty() && !f.depth.empty()) {
      frames_.push_back(f);
      continue;
    }
    const std::string base = frame_name(f.number);
    const std::string problem =
        "frame folder '" + folder_ + "': frame " + std::to_string(f.number) + " has " +
        (f.depth.empty() ? "no depth image " + base + ".depth.png" : "no colour image " + base + ".color.png or .jpg") +
        " (its files: " + f.colour + (f.colour.empty() ? "" : " ") + f.depth + (f.depth.empty() ? "" : " ") + f.pose +
        ")";
    if (!params.skip_bad_frames)
      throw InputError(problem + "; add it, remove the frame's other files, or set input.skip_bad_frames: true");
    ++skipped_;
    spdlog::warn("{}: skipped (input.skip_bad_frames)", problem);
  }
  if (frames_.empty())
    throw InputError("frame folder '" + folder_ +
                     "' has no frames (no frame-NNNNNN.color.png/.jpg with a frame-NNNNNN.depth.png)");
  select_frames(frames_, params.first_frame, params.max_frames, folder_);

  std::int64_t with_pose = 0, lost_pose = 0;
  for (const FrameFolderEntry& f : frames_) {
    poses_.push_back(f.pose.empty() ? std::nullopt : read_pose_matrix((fs::path(folder_) / f.pose).string()));
    with_pose += poses_.back().has_value();
    lost_pose += !f.pose.empty() && !poses_.back();
  }
  if (const std::string g = find_here_or_above(folder_, "gravity-direction.txt"); !g.empty()) {
    gravity_ = read_gravity_direction(g);
    if (with_pose == 0)
      spdlog::warn("'{}' gives gravity in the poses' world frame, but no frame has a pose: gravity unused", g);
  }

  const IntrinsicsChoice choice =
      resolve_intrinsics(params.intrinsics, folder_);  // logged (a warning for the generic set)
  K_ = choice.K, flip_x_ = choice.flip_x, flip_y_ = choice.flip_y;
  spdlog::info(
      "frame folder '{}': {} frames (numbers {}..{}), {} with a pose file{}{}, depth {} units per metre{}, "
      "timestamps number / {} fps",
      folder_, frames_.size(), frames_.front().number, frames_.back().number, with_pose,
      lost_pose ? " (" + std::to_string(lost_pose) + " more marked lost)" : "",
      gravity_ ? ", gravity from gravity-direction.txt" : "", scale_,
      params.depth_scale > 0 ? " (input.depth_scale)" : " (the layout's millimetres; input.depth_scale 0)", params.fps);
  scale_check_ = std::make_unique<DepthScaleCheck>(scale_, params.check_depth_scale);
}

FrameFolderSource::~FrameFolderSource() = default;

void FrameFolderSource::load_frame(std::size_t i, RgbdFrame& frame) {
  const FrameFolderEntry& f = frames_[i];
  const fs::path dir(folder_);
  const std::string depth_path = (dir / f.depth).string(), colour_path = (dir / f.colour).string();
  RawRgbdPair pair = read_rgbd_pair(depth_path, colour_path, K_, flip_x_, flip_y_);
  reserve_frame_images(frame, pair.depth.width(), pair.depth.height(), pinned_);
  decode_depth(pair.depth, scale_, depth_path, params_.fill_gaps, delivered_ == 0, gap_scratch_, *scale_check_,
               frame.depth);
  frame.rgb.buffer().copy_from(pair.colour.buffer());
  frame.timestamp = static_cast<double>(f.number) / params_.fps;
  frame.intrinsics = K_;
  frame.ground_truth = poses_[i];
  frame.accelerometer.reset();
  // At rest an accelerometer reads the specific force, opposite to gravity, in its own axes.
  if (gravity_ && poses_[i]) frame.accelerometer = (transpose(poses_[i]->R) * *gravity_) * -kStandardGravity;
}

bool FrameFolderSource::next(RgbdFrame& frame) {
  while (next_ < frames_.size()) {
    const std::size_t i = next_++;
    try {
      load_frame(i, frame);
      frame.index = delivered_++;
      return true;
    } catch (const Error& e) {
      const bool scale_problem = std::string(e.what()).find("input.depth_scale") != std::string::npos;
      if (!params_.skip_bad_frames || scale_problem) throw;  // a wrong scale is not one bad frame
      ++skipped_;
      spdlog::warn("skipping bad frame {} of '{}' ({} skipped so far): {}", frames_[i].number, folder_, skipped_,
                   e.what());
    }
  }
  return false;
}

}  // namespace seamless
