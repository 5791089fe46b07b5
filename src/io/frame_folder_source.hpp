// A "frame folder", the layout of Microsoft's 7-Scenes, 3DMatch's RGB-D sequences and the
// tsdf-fusion demos: one set of files per frame,
//   frame-NNNNNN.color.png | .color.jpg   colour, 8-bit RGB (PNG or JPEG, told apart by content)
//   frame-NNNNNN.depth.png                depth, 16-bit, millimetres by default (0 and 65535: none)
//   frame-NNNNNN.pose.txt                 optional: 4x4 camera-to-world matrix, row-major, metres
// plus, in the folder or its parent, camera-intrinsics.txt or intrinsics.K.txt (3x3 K) and
// gravity-direction.txt (the direction of gravity in the poses' world frame). Frame numbers may
// have gaps; frames are taken in the order of their numbers. See docs/INPUT.md.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "io/frame_source.hpp"
#include "io/input_params.hpp"

namespace seamless {

class DepthScaleCheck;

// The files of one frame number, names relative to the folder ("" where the folder has none).
struct FrameFolderEntry {
  std::int64_t number = 0;
  std::string colour, depth, pose;
};

// Every frame-<digits>.{color.png,color.jpg,color.jpeg,depth.png,pose.txt} in `folder`, by number;
// other files are ignored. Throws an Error for a folder that does not exist and for a number with two
// colour images (which one is meant?).
std::vector<FrameFolderEntry> list_frame_folder(const std::string& folder);

// A 4x4 camera-to-world matrix, 16 numbers row by row. nullopt when it holds a non-finite number
// (ScanNet-style "-inf" marks a frame whose pose the capture lost). Throws an Error naming the file
// for another count, a bottom row that is not 0 0 0 1, or an upper-left 3x3 that is no rotation
// (columns not orthonormal to 1e-2, or a reflection); a rotation within that is re-orthonormalised
// (the nearest rotation, by SVD: poses saved in float drift off SO(3)).
std::optional<SE3> read_pose_matrix(const std::string& path);

// gravity-direction.txt: three numbers, the direction gravity pulls in the poses' world frame;
// returned as a unit vector. Throws an Error naming the file for another count or a zero vector.
vec3 read_gravity_direction(const std::string& path);

class FrameFolderSource : public FrameSource {
 public:
  // pinned: frames in page-locked host memory (for a GPU pipeline; make_source decides).
  explicit FrameFolderSource(const InputParams& params, bool pinned = false);
  ~FrameFolderSource() override;
  bool next(RgbdFrame& frame) override;
  std::optional<std::int64_t> size() const override { return static_cast<std::int64_t>(frames_.size()); }
  std::string name() const override { return "frames:" + folder_; }
  Intrinsics intrinsics() const override { return K_; }
  std::int64_t skipped_frames() const override { return skipped_; }
  const std::vector<FrameFolderEntry>& frames() const { return frames_; }
  // The pose files' matrices (camera to world), one per frame; nullopt where a frame has none.
  const std::vector<std::optional<SE3>>& poses() const { return poses_; }
  // Gravity in the poses' world frame, from gravity-direction.txt.
  const std::optional<vec3>& gravity_direction() const { return gravity_; }

 private:
  void load_frame(std::size_t i, RgbdFrame& frame);

  InputParams params_;
  std::string folder_;
  Intrinsics K_;
  bool flip_x_ = false, flip_y_ = false;  // images flipped on reading (a negative focal length)
  double scale_ = 1000.0;                 // units per metre, input.depth_scale or the layout's millimetres
  std::vector<FrameFolderEntry> frames_;
  std::vector<std::optional<SE3>> poses_;
  std::optional<vec3> gravity_;
  std::unique_ptr<DepthScaleCheck> scale_check_;
  Image<float> gap_scratch_;  // input.fill_gaps: the depth before its gaps are filled
  bool pinned_ = false;
  std::size_t next_ = 0;
  std::int64_t delivered_ = 0;
  std::int64_t skipped_ = 0;
};

}  // namespace seamless
