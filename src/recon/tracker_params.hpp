// Tracker section (`tracker:`): camera tracking after KinectFusion (Newcombe et al. 2011):
// projective data association, point-to-plane ICP over a 3-level pyramid; plus an RGB-D variant.
#pragma once
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/math.hpp"
#include "core/params.hpp"

namespace seamless {

// RGB-D weighting choices, shared by tracker: and refine:.
enum class RgbdWeighting { fixed, robust };
inline std::span<const EnumName<RgbdWeighting>> enum_names(RgbdWeighting) {
  static constexpr EnumName<RgbdWeighting> names[] = {{RgbdWeighting::fixed, "fixed"},
                                                      {RgbdWeighting::robust, "robust"}};
  return names;
}
enum class DepthNoiseModel { uniform, depth_squared };
inline std::span<const EnumName<DepthNoiseModel>> enum_names(DepthNoiseModel) {
  static constexpr EnumName<DepthNoiseModel> names[] = {{DepthNoiseModel::uniform, "uniform"},
                                                        {DepthNoiseModel::depth_squared, "depth_squared"}};
  return names;
}
enum class PhotometricPixels { inliers, visible };
inline std::span<const EnumName<PhotometricPixels>> enum_names(PhotometricPixels) {
  static constexpr EnumName<PhotometricPixels> names[] = {{PhotometricPixels::inliers, "inliers"},
                                                          {PhotometricPixels::visible, "visible"}};
  return names;
}

// Frame to model (KinectFusion: against the raycast of the fused volume) or to the previous frame.
enum class TrackingMode { frame_to_model, frame_to_frame };
inline std::span<const EnumName<TrackingMode>> enum_names(TrackingMode) {
  static constexpr EnumName<TrackingMode> names[] = {{TrackingMode::frame_to_model, "frame_to_model"},
                                                     {TrackingMode::frame_to_frame, "frame_to_frame"}};
  return names;
}
// What an rgbd frame-to-model step's photometric term compares with.
enum class PhotometricReference { model, frame };
inline std::span<const EnumName<PhotometricReference>> enum_names(PhotometricReference) {
  static constexpr EnumName<PhotometricReference> names[] = {{PhotometricReference::model, "model"},
                                                             {PhotometricReference::frame, "frame"}};
  return names;
}
// Where "down" comes from (`automatic` is written "auto": a C++ keyword).
enum class GravitySource { automatic, accelerometer, floor, fixed, none };
inline std::span<const EnumName<GravitySource>> enum_names(GravitySource) {
  static constexpr EnumName<GravitySource> names[] = {{GravitySource::automatic, "auto"},
                                                      {GravitySource::accelerometer, "accelerometer"},
                                                      {GravitySource::floor, "floor"},
                                                      {GravitySource::fixed, "fixed"},
                                                      {GravitySource::none, "none"}};
  return names;
}

struct TrackerParams {
  std::string kind = "icp";
  TrackingMode mode = TrackingMode::frame_to_model;
  std::vector<int> iterations{10, 5, 4};  // finest level first (KinectFusion, sec. 3.5)
  // Per level, finest first: the reduction visits every n-th pixel of every n-th row (levels not
  // listed: every pixel). The CPU's cost is the finest level's pixels (docs/TRACKING.md, "Pixel stride").
  std::vector<int> pixel_stride{1};
  // A level stops early once a Gauss-Newton step is below both: a tenth of a millimetre, and a
  // rotation that moves a point 1.7 m away by as much; an order of magnitude under the Kinect v1's
  // depth noise at 1 m (~1.4 mm, Khoshelham & Elberink 2012), so the pose it would still gain is far
  // below what the sensor resolves. 0 and 0: every level takes all its iterations.
  float stop_translation = 1e-4f;     // metres per step
  float stop_rotation_deg = 0.0034f;  // degrees per step (6e-5 rad)
  float dist_threshold = 0.1f;        // metres
  // Depth beyond this takes no part in tracking (current and reference points alike); 0: no cut.
  // 4 m is the range the structured-light sensors are specified for and the one OpenCV's RGB-D
  // odometries cut at: beyond it the Kinect v1 / Xtion depth noise exceeds 2 cm (Khoshelham &
  // Elberink 2012: sigma_z ~ 1.4 mm z^2). Alone it did not win on every folder (docs/TRACKING.md).
  float max_depth = 0.f;
  // Frame to frame only: the reference stays the last keyframe until a frame's inlier ratio against it
  // falls below this fraction of the ratio the first frame tracked against it had (its overlap with
  // the keyframe dropped); then that frame becomes the keyframe (as DVO SLAM tracks against keyframes,
  // Kerl et al. 2013). Fewer reference changes, less drift. 0: every tracked frame is the reference.
  float keyframe_min_overlap = 0.f;
  float angle_threshold_deg = 20.f;
  float photometric_weight = 0.1f;        // rgbd only: weight of the colour term vs geometry
  float min_inlier_ratio = 0.15f;         // see docs/TRACKING.md, "Tracking loss"
  float min_inlier_ratio_vs_last = 0.5f;  // a sudden drop below this fraction of the last good frame's ratio
  double max_condition = 1e6;             // of the finest level's 6x6 system (see docs/TRACKING.md)
  float max_intensity_diff = 0.3f;        // rgbd: larger photometric residuals are outliers
  // rgbd frame_to_model: the model's colour (consistent with the model geometry) or the last tracked
  // frame's image (sharper, but tied to that frame's estimated pose: see docs/TRACKING.md).
  PhotometricReference photometric_reference = PhotometricReference::model;
  // rgbd: fixed weights (photometric_weight), or robust self-balancing ones: each residual type
  // whitened by its own scale, estimated every step, with Student-t weights against outliers
  // (Kerl et al. 2013; docs/TRACKING.md, "RGB-D").
  RgbdWeighting weighting = RgbdWeighting::fixed;
  float robust_dof = 5.f;  // degrees of freedom of the t-distribution (Kerl et al. 2013: 5)
  DepthNoiseModel depth_noise = DepthNoiseModel::uniform;  // robust: geometric noise uniform or ~ depth^2 (Kinect v1)
  // rgbd: the pixels that get a photometric row (kernels/recon/rgbd.hpp, RgbdLevel): the geometric
  // inliers only, or every pixel that sees the reference surface (the normal test left to geometry).
  PhotometricPixels photometric_pixels = PhotometricPixels::inliers;
  float min_gradient = 0.f;            // rgbd: photometric rows only where |grad I| >= this (per pixel)
  bool constant_velocity = false;      // start each frame from the last motion instead of the last pose
  float max_translation_jump = 0.3f;   // metres per frame
  float max_rotation_jump_deg = 30.f;  // degrees per frame
  // Relocalisation: the first frame tracked after lost ones is accepted only when its pose is within
  // what a handheld camera can move in the time since the last good frame, and its residual against
  // the model is within relocalise_max_residual_ratio of the recent good frames' (docs/TRACKING.md,
  // "Relocalisation"). The speeds are above the fastest handheld motion of the TUM benchmark: its
  // freiburg1 sequences average at most 0.43 m/s (fr1/desk2) and 50 deg/s (fr1/rpy) (Sturm et al.
  // 2012, Table I), and fr1/rpy peaks at ~6 degrees in one 1/30 s frame (180 deg/s).
  float relocalise_max_speed = 1.0f;               // m/s
  float relocalise_max_angular_speed_deg = 180.f;  // deg/s
  float relocalise_max_residual_ratio = 2.0f;
  GravitySource gravity = GravitySource::automatic;
  vec3 fixed_gravity{0.f, 1.f, 0.f};  // camera frame (y down), used when gravity: fixed
  // kind trajectory: the poses to fuse from, a TUM trajectory file (world_T_camera), each frame's
  // taken at its timestamp as the ground truth's is (interpolated between samples at most
  // trajectory_max_gap apart; a frame outside the file is not fused).
  std::string trajectory;
  double trajectory_max_gap = 0.1;  // seconds, input.max_gt_gap's default

  // Rules across keys, checked when a config is loaded (Experiment::validate); tracker_gravity.cpp
  // checks the vector again for code that builds TrackerParams without a config.
  void validate() const {
    std::vector<std::string> problems;
    check(problems);
    if (!problems.empty()) throw ConfigError(problems.front());
  }
  // The same, every problem appended to `problems` (config loading lists them all at once).
  void check(std::vector<std::string>& problems) const {
    if (gravity == GravitySource::fixed && length2(fixed_gravity) == 0.f)
      problems.push_back("tracker.gravity: fixed needs a direction, but tracker.fixed_gravity is the zero vector");
    // Our own trackers align over the pyramid levels listed: none, or no iteration on any, tracks
    // nothing and every frame after the first would be lost.
    const bool own = kind == "icp" || kind == "rgbd";
    bool any = false;
    for (int n : iterations) any = any || n > 0;
    if (own && !any)
      problems.push_back(
          "tracker.iterations: " + std::string(iterations.empty() ? "empty" : "no level has an iteration") +
          "; give ICP iterations per pyramid level, finest first, at least one level above 0 "
          "(default [10, 5, 4])");
    if (kind == "trajectory" && trajectory.empty())
      problems.push_back(
          "tracker.kind: trajectory fuses from a given trajectory, but tracker.trajectory names no file (a TUM "
          "trajectory, e.g. a `seamless track` run's trajectory.txt)");
  }

  template <class V> void visit(V& v) {
    v("kind", kind, "tracker; opencv_* and pcl_gicp are external libraries, always frame to frame",
      Choices{"icp", "rgbd", "ground_truth", "trajectory", "opencv_rgbd_odometry", "opencv_icp", "opencv_rgbd_icp",
              "opencv_fast_icp", "pcl_gicp"});
    v("mode", mode, "align to the model raycast or to the previous frame");
    v("iterations", iterations, "ICP iterations per pyramid level, finest first", Range{0, 1000});
    v("pixel_stride", pixel_stride,
      "per pyramid level, finest first: track on every n-th pixel of every n-th row (a full-resolution "
      "subsample); levels not listed use every pixel",
      Range{1, 64});
    v("stop_translation", stop_translation,
      "a pyramid level stops iterating once a step translates less than this (metres) and rotates less than "
      "stop_rotation_deg; 0 and 0: always all iterations",
      Range{0.0, 1.0});
    v("stop_rotation_deg", stop_rotation_deg, "see stop_translation (degrees)", Range{0.0, 180.0});
    v("dist_threshold", dist_threshold, "reject correspondences farther apart, metres", Range{0.0, 10.0});
    v("max_depth", max_depth,
      "depth farther than this (metres) takes no part in tracking, current and reference points alike; 0: no "
      "cut (4: the range of structured-light sensors, and OpenCV's odometries' cut)",
      Range{0.0, 100.0});
    v("keyframe_min_overlap", keyframe_min_overlap,
      "frame to frame: track against the last keyframe until a frame's inlier ratio falls below this fraction "
      "of the first frame's against it, then make that frame the keyframe; 0: every frame is the next reference",
      Range{0.0, 1.0});
    v("angle_threshold_deg", angle_threshold_deg, "reject correspondences whose normals differ more, degrees",
      Range{0.0, 180.0});
    v("photometric_weight", photometric_weight, "weight of the photometric term (rgbd)", Range{0.0, 1e6});
    v("min_inlier_ratio", min_inlier_ratio, "tracking is lost below this fraction of inliers", Range{0.0, 1.0});
    v("min_inlier_ratio_vs_last", min_inlier_ratio_vs_last,
      "tracking is lost when the inlier ratio falls below this fraction of the last good frame's (a cut)",
      Range{0.0, 1.0});
    v("max_condition", max_condition,
      "tracking is lost when the condition number of the 6x6 ICP system exceeds this (degenerate geometry)",
      Range{1.0, 1e30});
    v("max_intensity_diff", max_intensity_diff, "rgbd: photometric residuals larger than this are outliers",
      Range{0.0, 1.0});
    v("photometric_reference", photometric_reference,
      "rgbd frame_to_model: the photometric term compares with the model raycast's fused colour or with the "
      "last tracked frame's image");
    v("weighting", weighting,
      "rgbd: fixed (photometric_weight) or robust (each term whitened by its own residual scale, estimated "
      "every step, with t-distribution weights against outliers; photometric_weight then scales the whitened "
      "colour term)");
    v("robust_dof", robust_dof, "rgbd weighting robust: degrees of freedom of the t-distribution", Range{0.1, 1e6});
    v("depth_noise", depth_noise,
      "rgbd weighting robust: the geometric residual's noise is uniform, or grows with depth squared "
      "(structured-light sensors such as the Kinect v1)");
    v("photometric_pixels", photometric_pixels,
      "rgbd: photometric rows for the geometric inliers only, or for every pixel whose projection sees the "
      "reference surface within dist_threshold (the normal test then applies to the geometric rows only)");
    v("min_gradient", min_gradient,
      "rgbd: photometric rows only where the reference intensity gradient is at least this, intensity [0, 1] "
      "per pixel (central difference); 0: every pixel",
      Range{0.0, 1.0});
    v("constant_velocity", constant_velocity, "predict each pose from the previous motion (else from the last pose)");
    v("max_translation_jump", max_translation_jump, "tracking is lost above this per-frame motion, metres",
      Range{0.0, 100.0});
    v("max_rotation_jump_deg", max_rotation_jump_deg, "tracking is lost above this per-frame rotation, degrees",
      Range{0.0, 180.0});
    v("relocalise_max_speed", relocalise_max_speed,
      "after lost frames, a frame is accepted only if its pose moved at most this speed (m/s) times the time "
      "since the last good frame, plus 2 cm",
      Range{0.0, 100.0});
    v("relocalise_max_angular_speed_deg", relocalise_max_angular_speed_deg,
      "after lost frames, a frame is accepted only if it turned at most this (deg/s) times the time since the "
      "last good frame, plus 2 degrees",
      Range{0.0, 100000.0});
    v("relocalise_max_residual_ratio", relocalise_max_residual_ratio,
      "after lost frames, a frame is accepted only if its residual against the model is at most this multiple "
      "of the median of the last 10 good frames' (0: no residual test)",
      Range{0.0, 1000.0});
    v("gravity", gravity, "where 'down' comes from (auto: accelerometer if present, else floor plane)");
    v("fixed_gravity", fixed_gravity, "down direction in the first camera frame (gravity: fixed)");
    v("trajectory", trajectory,
      "kind trajectory: TUM trajectory file whose poses are fused (world_T_camera; timestamps matched like the "
      "ground truth's)");
    v("trajectory_max_gap", trajectory_max_gap,
      "kind trajectory: interpolate a frame's pose only between samples at most this far apart, seconds; 0: "
      "exact timestamps only",
      Range{0.0, 1e6});
  }
};

}  // namespace seamless
