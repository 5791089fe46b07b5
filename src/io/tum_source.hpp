// A TUM RGB-D benchmark folder (Sturm et al., IROS 2012): rgb.txt, depth.txt, optional
// associations.txt / associate.txt, groundtruth.txt and accelerometer.txt, rgb/ and depth/ PNGs.
#pragma once
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "io/trajectory.hpp"

namespace seamless {

class DepthScaleCheck;

// One line of a TUM list file (rgb.txt, depth.txt): `timestamp filename`.
struct TumListEntry {
  double timestamp;
  std::string file;
};
// Throws seamless::Error naming file and line for a malformed line or timestamps out of order.
std::vector<TumListEntry> read_tum_list(const std::string& path);

struct TumPair {
  TumListEntry rgb, depth;
};
// Pairs rgb and depth like TUM's associate.py: all candidate pairs with |t_rgb - (t_depth + offset)|
// below max_difference seconds, taken greedily by increasing difference, each image used once,
// sorted by rgb time.
std::vector<TumPair> associate(const std::vector<TumListEntry>& rgb, const std::vector<TumListEntry>& depth,
                               double max_difference = 0.02, double offset = 0.0);
// The pairs a TUM folder's frames are made of, per input.association (auto or file; see
// docs/INPUT.md). Logs one warning when an association file disagrees with pairing by time.
std::vector<TumPair> tum_folder_pairs(const std::string& folder, const InputParams& params);

class TumSource : public FrameSource {
 public:
  // pinned: frames in page-locked host memory (for a GPU pipeline; make_source decides).
  explicit TumSource(const InputParams& params, bool pinned = false);
  ~TumSource() override;
  bool next(RgbdFrame& frame) override;
  std::optional<std::int64_t> size() const override { return static_cast<std::int64_t>(pairs_.size()); }
  std::string name() const override { return "tum:" + folder_; }
  Intrinsics intrinsics() const override;
  std::int64_t skipped_frames() const override { return skipped_; }
  const std::vector<TumPair>& pairs() const { return pairs_; }
  bool has_ground_truth() const { return !groundtruth_.empty(); }
  // Timestamp, intrinsics, accelerometer and ground truth of pair i, without decoding its images.
  RgbdFrame metadata(std::size_t i) const;

 private:
  void load_frame(const TumPair& pair, RgbdFrame& frame);
  void fill_metadata(const TumPair& pair, RgbdFrame& frame) const;
  std::optional<vec3> accelerometer_at(double t) const;

  InputParams params_;
  std::string folder_;
  Intrinsics K_;                          // as calibrated (with distortion)
  bool flip_x_ = false, flip_y_ = false;  // images flipped on reading (a negative focal length)
  std::vector<TumPair> pairs_;
  Trajectory groundtruth_;
  std::vector<std::pair<double, vec3>> accel_;    // camera-frame specific force
  Image<vec2> undistort_map_;                     // where each undistorted pixel comes from
  Image<uchar3> rgb_scratch_;                     // undistortion's source
  Image<float> scratch_;                          // depth before undistortion
  Image<float> gap_scratch_;                      // input.fill_gaps: depth before its gaps are filled
  std::unique_ptr<DepthScaleCheck> scale_check_;  // depth_scale against the first frames' quantisation
  bool pinned_ = false;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::int64_t skipped_ = 0;
};

}  // namespace seamless
