#include "recon/tracker_sequence.hpp"

#include <cstdio>
#include <filesystem>
#include <optional>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/log.hpp"
#include "core/output_file.hpp"
#include "core/timing.hpp"
#include "io/png_io.hpp"

// The tracker registry and the whole-sequence driver track_sequence() with its outputs
// (trajectory.txt, groundtruth.txt, tracking_stats.csv, dynamic masks); the per-frame state
// machine it drives, TrackingSession, is in tracking_session.cpp.
namespace seamless {

// ---- registry -----------------------------------------------------------------------------------

namespace {
// An external tracker's entry: available when its factory was compiled in.
TrackerInfo external_entry(std::string kind, std::string description, external::OdometryFactory make,
                           std::string missing) {
  bool on = static_cast<bool>(make);
  return {std::move(kind), std::move(description), on, on ? "" : std::move(missing), std::move(make)};
}
const char* kOpenCvMissing =
    "OpenCV's rgbd contrib module is not in this build (apt-get install libopencv-contrib-dev, rebuild)";
const char* kPclMissing = "PCL is not in this build (apt-get install libpcl-dev, rebuild)";
}  // namespace

const std::vector<TrackerInfo>& tracker_registry() {
  using external::OpenCvMethod;
  static const std::vector<TrackerInfo> r = {
      {"icp", "point-to-plane ICP, projective association, 3-level pyramid (KinectFusion)", true, "", {}},
      {"rgbd", "ICP plus a photometric term in one Gauss-Newton solve", true, "", {}},
      {"ground_truth", "the source's ground-truth poses (upper bound for fusion and physics)", true, "", {}},
      {"trajectory", "the poses of a TUM trajectory file (tracker.trajectory), e.g. a refined one", true, "", {}},
      external_entry("opencv_rgbd_odometry", "OpenCV contrib rgbd::RgbdOdometry (photometric), frame to frame",
                     external::opencv_factory(OpenCvMethod::rgbd), kOpenCvMissing),
      external_entry("opencv_icp", "OpenCV contrib rgbd::ICPOdometry, frame to frame",
                     external::opencv_factory(OpenCvMethod::icp), kOpenCvMissing),
      external_entry("opencv_rgbd_icp", "OpenCV contrib rgbd::RgbdICPOdometry, frame to frame",
                     external::opencv_factory(OpenCvMethod::rgbd_icp), kOpenCvMissing),
      external_entry("opencv_fast_icp", "OpenCV contrib rgbd::FastICPOdometry (kinfu's ICP), frame to frame",
                     external::opencv_factory(OpenCvMethod::fast_icp), kOpenCvMissing),
      external_entry("pcl_gicp", "PCL generalized ICP on a 2 cm voxel grid, frame to frame",
                     external::pcl_gicp_factory(), kPclMissing),
  };
  return r;
}

void require_tracker(const std::string& kind) { (void)tracker_info(kind); }

const TrackerInfo& tracker_info(const std::string& kind) {
  for (const TrackerInfo& t : tracker_registry()) {
    if (t.kind != kind) continue;
    if (!t.available) throw ConfigError("tracker.kind '" + kind + "' is not available in this build: " + t.missing);
    return t;
  }
  std::string known;
  for (const TrackerInfo& t : tracker_registry()) known += (known.empty() ? "" : ", ") + t.kind;
  throw ConfigError("tracker.kind '" + kind + "' is unknown; known trackers: " + known);
}

void write_tracking_stats(const std::string& path, const std::vector<FrameRecord>& frames) {
  std::FILE* f = std::fopen(partial_path(path).c_str(), "w");
  if (!f) throw Error("cannot write tracking statistics '" + path + "': check that the folder exists and is writable");
  std::fprintf(f,
               "frame,timestamp,status,fused,inlier_ratio,inliers,residual_rms,condition,iterations,"
               "translation_jump_m,rotation_jump_deg,preprocess_ms,track_ms,fuse_ms,frame_ms\n");
  for (const FrameRecord& r : frames) {
    const TrackResult& t = r.result;
    std::fprintf(f, "%lld,%.6f,%s,%d,%.5f,%lld,%.6g,%.6g,%d,%.6f,%.4f,%.3f,%.3f,%.3f,%.3f\n",
                 static_cast<long long>(r.frame), r.timestamp, to_string(t.status), r.fused ? 1 : 0, t.inlier_ratio,
                 static_cast<long long>(t.inliers), t.residual_rms, t.condition, t.iterations, t.translation_jump,
                 t.rotation_jump_deg, r.preprocess_ms, r.track_ms, r.fuse_ms, r.frame_ms);
  }
  if (std::fclose(f) != 0) throw Error("error writing tracking statistics '" + path + "' (disk full?)");
  commit_partial(path);
}

namespace {
// The warning for a frame that tracking lost.
void log_lost(const FrameRecord& rec) {
  if (rec.result.ok()) return;
  spdlog::warn("frame {}: tracking lost ({}, inliers {:.2f}, condition {:.3g}, jump {:.3f} m / {:.1f} deg); not fused",
               rec.frame, to_string(rec.result.status), rec.result.inlier_ratio, rec.result.condition,
               rec.result.translation_jump, rec.result.rotation_jump_deg);
}
}  // namespace

std::optional<MaskQuality> mask_quality(const std::vector<FrameRecord>& frames, const std::vector<int>& people) {
  std::vector<std::pair<std::int64_t, MaskScore>> scores;
  for (const FrameRecord& f : frames)
    if (f.mask_score) scores.push_back({f.frame, *f.mask_score});
  return mask_quality(scores, people);
}

void write_dynamic_mask(const std::string& out_dir, std::int64_t index, const TrackingSession& session) {
  const std::string dir = out_dir + "/dynamic_mask";
  std::filesystem::create_directories(dir);
  char name[32];
  std::snprintf(name, sizeof name, "/%06lld.png", static_cast<long long>(index));
  Image<std::uint8_t> png(session.pyramid().level(0).K.width, session.pyramid().level(0).K.height, Device::CPU);
  std::vector<std::uint8_t> m(static_cast<std::size_t>(png.width()) * png.height(), 0);
  if (session.dynamic_mask().width() == png.width()) m = session.dynamic_mask().to_host();
  for (std::uint8_t& v : m) v = v ? 255 : 0;
  png.buffer().copy_from_host(m.data(), static_cast<std::int64_t>(m.size()));
  write_png_u8(dir + name, png);
}

TrackSequenceResult track_sequence(FrameSource& source, const TrackSequenceParams& params, Device device,
                                   const std::string& out_dir, Volume* volume,
                                   const std::function<void(const RgbdFrame&, const FrameRecord&)>& on_frame) {
  TrackingSession session(params, device, source.intrinsics(), volume);
  std::unique_ptr<TrajectoryWriter> writer;
  if (params.write_files) {
    std::filesystem::create_directories(out_dir);
    writer = std::make_unique<TrajectoryWriter>(
        out_dir + "/trajectory.txt", "camera trajectory (world_T_camera) by seamless, tracker " + params.tracker.kind +
                                         " " + enum_name(params.tracker.mode));
  }
  TrackSequenceResult out;
  RgbdFrame frame;
  std::vector<double> track_ms, frame_ms;
  // The source's own poses, for evaluation: groundtruth.txt in this run's world frame (the first
  // frame's ground truth maps onto its pose, the map the ground_truth tracker uses), at the same
  // timestamps as trajectory.txt, so `seamless eval trajectory.txt groundtruth.txt` pairs them all.
  std::unique_ptr<TrajectoryWriter> gt_writer;
  SE3 world_T_gt = SE3::identity();
  // Frames still wanted: up to max_frames, and none after Ctrl-C / SIGTERM (the frame being
  // processed when the signal came is finished first).
  auto wanted = [&] {
    return (params.max_frames <= 0 || static_cast<std::int64_t>(out.frames.size()) < params.max_frames) &&
           !interrupted();
  };
  try {
    while (wanted() && source.next(frame)) {
      FrameRecord rec = session.process(frame);
      if (params.corrector)
        if (std::optional<SE3> delta = params.corrector->after_frame(frame, rec)) session.correct(*delta);
      out.trajectory.push_back(TumPose::from_se3(frame.timestamp, rec.result.world_T_camera));
      if (writer) writer->write(out.trajectory.back());
      if (out.frames.empty() && frame.ground_truth)
        world_T_gt = rec.result.world_T_camera * frame.ground_truth->inverse();
      if (frame.ground_truth) {
        out.ground_truth.push_back(TumPose::from_se3(frame.timestamp, world_T_gt * *frame.ground_truth));
        if (params.write_files && !gt_writer)
          gt_writer = std::make_unique<TrajectoryWriter>(
              out_dir + "/groundtruth.txt", "ground truth of " + source.name() +
                                                " (world_T_camera), in the world frame of trajectory.txt: the first "
                                                "frame's ground truth is its pose there");
        if (gt_writer) gt_writer->write(out.ground_truth.back());
      }
      if (params.write_files && params.dynamic.write_masks) write_dynamic_mask(out_dir, frame.index, session);
      if (out.frames.size() > 0) track_ms.push_back(rec.track_ms);
      frame_ms.push_back(rec.frame_ms);
      if (!params.frame_poses) log_lost(rec);  // a fusion pass's skipped frames were reported when tracked
      if (on_frame) on_frame(frame, rec);
      out.frames.push_back(rec);
    }
  } catch (...) {
    // A frame that cannot be read or processed ends the run; the frames before it are kept.
    const auto n = static_cast<long long>(out.frames.size());
    if (params.write_files) {
      try {
        writer.reset();  // trajectory.txt under its own name
        gt_writer.reset();
        write_tracking_stats(out_dir + "/tracking_stats.csv", out.frames);
      } catch (const std::exception& e) {
        spdlog::error("{}", e.what());
      }
      if (n > 0)
        spdlog::error("the run stopped at frame {}: trajectory.txt and tracking_stats.csv hold frames 0-{} before it",
                      n, n - 1);
      else spdlog::error("the run stopped at frame 0, before any frame was tracked");
    } else {
      spdlog::error("the run stopped at frame {}, after {} frames", n, n);
    }
    throw;
  }
  if (interrupted()) spdlog::warn("tracking stopped after {} frames (interrupted)", out.frames.size());
  out.lost_frames = session.lost_frames();
  out.gravity = session.gravity();
  out.median_track_ms = median(track_ms);
  out.median_frame_ms = median(frame_ms);
  if (params.keep_model_mesh && !volume && session.volume()) out.model_mesh = session.volume()->extract_mesh();
  if (writer) writer->close();
  if (gt_writer) gt_writer->close();
  if (params.write_files) write_tracking_stats(out_dir + "/tracking_stats.csv", out.frames);
  spdlog::info("tracked {} frames with {} ({}), {} lost; median {:.2f} ms tracking, {:.2f} ms a frame",
               out.frames.size(), params.tracker.kind, enum_name(params.tracker.mode), out.lost_frames,
               out.median_track_ms, out.median_frame_ms);
  return out;
}

}  // namespace seamless
