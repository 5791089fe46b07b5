#include "io/tum_source.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/log.hpp"
#include "io/depth_scale.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/jpeg_io.hpp"
#include "io/png_io.hpp"
#include "io/rgbd_pair.hpp"
#include "io/tum_text.hpp"
#include "kernels/io/undistort.hpp"

namespace seamless {
namespace fs = std::filesystem;
namespace {

using tum_text::for_each_data_line;
using tum_text::where;

// A line whose timestamp repeats the one before it (a list concatenated or edited twice) would make
// one frame two, fused twice with two poses at one time: it is dropped, with a warning naming it.
bool repeated(double prev, double t, const std::string& path, int n, const std::string& line) {
  if (t != prev) return false;
  spdlog::warn("{}: timestamp {:.6f} repeats the line before it; line dropped ('{}')", where(path, n), t, line);
  return true;
}

void check_order(double prev, double t, const std::string& path, int n) {
  if (t < prev)
    throw InputError("timestamps out of order at " + where(path, n) + " (" + std::to_string(t) + " after " +
                     std::to_string(prev) + "): TUM list files must be sorted by time");
}

// associations.txt: `t_rgb rgb_file t_depth depth_file` (TUM's associate.py rgb.txt depth.txt);
// a file written the other way round (depth first) is recognised by its file names.
std::vector<TumPair> read_associations(const std::string& path) {
  std::vector<TumPair> out;
  for_each_data_line(path, "association", [&](const std::string& line, int n) {
    std::istringstream ss(line);
    TumPair p;
    if (!(ss >> p.rgb.timestamp >> p.rgb.file >> p.depth.timestamp >> p.depth.file))
      throw InputError("malformed association at " + where(path, n) +
                       ": expected 't_rgb rgb/x.png t_depth depth/y.png', got '" + line + "'");
    if (p.rgb.file.find("depth") != std::string::npos && p.depth.file.find("rgb") != std::string::npos)
      std::swap(p.rgb, p.depth);
    if (!out.empty() && repeated(out.back().rgb.timestamp, p.rgb.timestamp, path, n, line)) return;
    if (!out.empty()) check_order(out.back().rgb.timestamp, p.rgb.timestamp, path, n);
    out.push_back(p);
  });
  return out;
}

std::vector<std::pair<double, vec3>> read_accelerometer(const std::string& path) {
  std::vector<std::pair<double, vec3>> out;
  for_each_data_line(path, "accelerometer", [&](const std::string& line, int n) {
    std::istringstream ss(line);
    double t, ax, ay, az;
    if (!(ss >> t >> ax >> ay >> az))
      throw InputError("malformed accelerometer sample at " + where(path, n) + ": expected 'timestamp ax ay az'");
    if (!out.empty()) check_order(out.back().first, t, path, n);
    // The Kinect's accelerometer axes are the camera's turned half a turn about z (x left, y up):
    // checked against the motion-capture ground truth of freiburg1 (tests/io/test_tum.cpp).
    out.push_back({t, vec3{static_cast<float>(-ax), static_cast<float>(-ay), static_cast<float>(az)}});
  });
  return out;
}

}  // namespace

std::vector<TumListEntry> read_tum_list(const std::string& path) {
  std::vector<TumListEntry> out;
  for_each_data_line(path, "TUM list", [&](const std::string& line, int n) {
    std::istringstream ss(line);
    TumListEntry e;
    if (!(ss >> e.timestamp >> e.file))
      throw InputError("malformed line at " + where(path, n) + ": expected 'timestamp filename', got '" + line + "'");
    if (!out.empty() && repeated(out.back().timestamp, e.timestamp, path, n, line)) return;
    if (!out.empty()) check_order(out.back().timestamp, e.timestamp, path, n);
    out.push_back(e);
  });
  return out;
}

std::vector<TumPair> associate(const std::vector<TumListEntry>& rgb, const std::vector<TumListEntry>& depth,
                               double max_difference, double offset) {
  struct Candidate {
    double diff;
    std::size_t r, d;
  };
  std::vector<Candidate> cand;
  for (std::size_t r = 0; r < rgb.size(); ++r) {  // both lists are sorted: a window per rgb entry
    const double t = rgb[r].timestamp - offset;   // the depth stamp that would match exactly
    auto lo = std::lower_bound(depth.begin(), depth.end(), t - max_difference,
                               [](const TumListEntry& e, double v) { return e.timestamp < v; });
    for (auto it = lo; it != depth.end() && it->timestamp <= t + max_difference; ++it) {
      const double diff = std::fabs(rgb[r].timestamp - (it->timestamp + offset));
      if (diff < max_difference) cand.push_back({diff, r, static_cast<std::size_t>(it - depth.begin())});
    }
  }
  std::stable_sort(cand.begin(), cand.end(), [](const Candidate& a, const Candidate& b) { return a.diff < b.diff; });
  std::vector<char> used_r(rgb.size(), 0), used_d(depth.size(), 0);
  std::vector<TumPair> out;
  for (const Candidate& c : cand) {
    if (used_r[c.r] || used_d[c.d]) continue;
    used_r[c.r] = used_d[c.d] = 1;
    out.push_back({rgb[c.r], depth[c.d]});
  }
  std::sort(out.begin(), out.end(),
            [](const TumPair& a, const TumPair& b) { return a.rgb.timestamp < b.rgb.timestamp; });
  return out;
}

namespace {

// associations.txt (written by `seamless record` and TUM's tools) or associate.txt; "" if neither.
std::string association_file(const fs::path& dir) {
  for (const char* name : {"associations.txt", "associate.txt"})
    if (fs::exists(dir / name)) return (dir / name).string();
  return "";
}

bool same_pairs(const std::vector<TumPair>& a, const std::vector<TumPair>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end(), [](const TumPair& x, const TumPair& y) {
    return x.rgb.file == y.rgb.file && x.depth.file == y.depth.file;
  });
}

}  // namespace

std::vector<TumPair> tum_folder_pairs(const std::string& folder, const InputParams& params) {
  const fs::path dir(folder);
  const std::string file = association_file(dir);
  if (params.association == Association::file) {
    if (file.empty())
      throw InputError("input.association is 'file' but '" + folder +
                       "' has neither associations.txt nor associate.txt: " +
                       "set input.association: auto to pair rgb.txt and depth.txt by time");
    return read_associations(file);
  }
  const bool lists = fs::exists(dir / "rgb.txt") && fs::exists(dir / "depth.txt");
  if (!lists && !file.empty()) return read_associations(file);  // nothing to pair by time
  std::vector<TumPair> pairs =
      associate(read_tum_list((dir / "rgb.txt").string()), read_tum_list((dir / "depth.txt").string()),
                params.association_max_dt, params.association_offset);
  if (!file.empty()) {
    std::vector<TumPair> listed = read_associations(file);
    if (!same_pairs(listed, pairs))
      spdlog::warn(
          "'{}' lists {} rgb/depth pairs, pairing rgb.txt and depth.txt by time (within {} s) finds {}: "
          "using the pairs by time, TUM's convention (input.association: auto); set input.association: file "
          "to use the file instead",
          file, listed.size(), params.association_max_dt, pairs.size());
  }
  return pairs;
}

TumSource::TumSource(const InputParams& params, bool pinned) : params_(params), folder_(params.path), pinned_(pinned) {
  if (folder_.empty()) throw InputError("input.path is empty: set it to a TUM RGB-D folder (source: tum)");
  if (!fs::is_directory(folder_))
    throw InputError("input.path '" + folder_ +
                     "' is not a folder: give the unpacked folder of a TUM RGB-D sequence (the one holding rgb.txt "
                     "and depth.txt; sequences at https://cvg.cit.tum.de/data/datasets/rgbd-dataset/download)");
  const IntrinsicsChoice choice = resolve_intrinsics(params.intrinsics, folder_);
  K_ = choice.K, flip_x_ = choice.flip_x, flip_y_ = choice.flip_y;
  fs::path dir(folder_);
  pairs_ = tum_folder_pairs(folder_, params);
  if (pairs_.empty())
    throw InputError("TUM folder '" + folder_ + "' has no rgb/depth pairs (input.association " +
                     enum_name(params.association) + ": no rgb/depth timestamps within input.association_max_dt " +
                     std::to_string(params.association_max_dt) +
                     " s, or empty lists); check rgb.txt and depth.txt, or input.association_offset");
  select_frames(pairs_, params.first_frame, params.max_frames, folder_);
  if (fs::exists(dir / "groundtruth.txt")) groundtruth_ = read_tum_trajectory((dir / "groundtruth.txt").string());
  if (fs::exists(dir / "accelerometer.txt")) accel_ = read_accelerometer((dir / "accelerometer.txt").string());
  scale_check_ = std::make_unique<DepthScaleCheck>(effective_depth_scale(params), params.check_depth_scale);
}

TumSource::~TumSource() = default;

Intrinsics TumSource::intrinsics() const {
  Intrinsics K = K_;
  bool distorted = false;
  for (float d : K.dist) distorted = distorted || d != 0.f;
  if (distorted && params_.undistort)
    for (float& d : K.dist) d = 0.f;
  return K;
}

std::optional<vec3> TumSource::accelerometer_at(double t) const {
  if (accel_.empty()) return std::nullopt;
  auto it = std::lower_bound(accel_.begin(), accel_.end(), t, [](const auto& a, double v) { return a.first < v; });
  auto best = it == accel_.end() ? it - 1 : it;
  if (it != accel_.begin() && std::fabs((it - 1)->first - t) < std::fabs(best->first - t)) best = it - 1;
  // The Kinect reports about 30 samples a second (TUM logs ~500 Hz with repeats): 0.1 s is near.
  if (std::fabs(best->first - t) > 0.1) return std::nullopt;
  return best->second;
}

void TumSource::load_frame(const TumPair& pair, RgbdFrame& frame) {
  fs::path dir(folder_);
  std::string depth_path = (dir / pair.depth.file).string(), rgb_path = (dir / pair.rgb.file).string();
  RawRgbdPair raw = read_rgbd_pair(depth_path, rgb_path, K_, flip_x_, flip_y_);
  const int w = raw.depth.width(), h = raw.depth.height();
  // Decoded straight into the frame's (reused, possibly page-locked) images; undistortion reads
  // from scratch images instead.
  Intrinsics K = intrinsics();
  const bool undistort = K.dist[0] == 0.f && K_.dist[0] != 0.f;
  reserve_frame_images(frame, w, h, pinned_);
  if (undistort && scratch_.width() != w) scratch_ = Image<float>(w, h, Device::CPU);
  Image<float>& depth = undistort ? scratch_ : frame.depth;
  decode_depth(raw.depth, effective_depth_scale(params_), depth_path, params_.fill_gaps, delivered_ == 0, gap_scratch_,
               *scale_check_, depth);
  const Image<uchar3>& rgb = raw.colour;
  if (undistort) {  // on the host: this is input decoding
    with_exec(Device::CPU, [&]<class E>(const E& ex) {
      if (undistort_map_.width() != depth.width()) {
        undistort_map_ = Image<vec2>(depth.width(), depth.height(), Device::CPU);
        kernels::Undistort<E>::undistort_map(ex, K_, undistort_map_.view());
      }
      kernels::Undistort<E>::remap_depth(ex, undistort_map_.cview(), depth.cview(), frame.depth.view());
      kernels::Undistort<E>::remap_rgb(ex, undistort_map_.cview(), rgb.cview(), frame.rgb.view());
    });
  } else {
    frame.rgb.buffer().copy_from(rgb.buffer());
  }
  fill_metadata(pair, frame);
}

void TumSource::fill_metadata(const TumPair& pair, RgbdFrame& frame) const {
  frame.timestamp = pair.rgb.timestamp;
  frame.intrinsics = intrinsics();
  frame.accelerometer = accelerometer_at(pair.rgb.timestamp);
  frame.ground_truth.reset();
  if (auto p = interpolate_pose(groundtruth_, pair.rgb.timestamp, params_.max_gt_gap)) frame.ground_truth = p->se3();
}

RgbdFrame TumSource::metadata(std::size_t i) const {
  RgbdFrame f;
  f.index = static_cast<std::int64_t>(i);
  fill_metadata(pairs_.at(i), f);
  return f;
}

bool TumSource::next(RgbdFrame& frame) {
  while (next_ < pairs_.size()) {
    const TumPair& pair = pairs_[next_++];
    try {
      load_frame(pair, frame);
      frame.index = delivered_++;
      return true;
    } catch (const Error& e) {
      bool scale_problem = std::string(e.what()).find("input.depth_scale") != std::string::npos;
      if (!params_.skip_bad_frames || scale_problem) throw;  // a wrong scale is not one bad frame
      ++skipped_;
      spdlog::warn("skipping bad frame {} of '{}' ({} skipped so far): {}", next_ - 1, folder_, skipped_, e.what());
    }
  }
  return false;
}

}  // namespace seamless
