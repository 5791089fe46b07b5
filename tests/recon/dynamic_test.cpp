// Configs/dynamic_person.yaml's scene (a person walking through the synthetic room at
// 0.8 m/s from 1 s to 4.9 s, a ball rolling behind them, then 3 s of empty room) with exact ground
// truth: the dynamic mask against the rendered mover masks, the ghost the person leaves in the
// mesh, and the tracking error, each with dynamic.enabled off and on. With a CUDA device the runs
// use it at the Kinect's 640x480, the resolution the mask and ghost bounds are for; on the CPU they are
// made small (320x240), and take tens of minutes: label slow. At 320x240 ICP itself tracks this
// orbit to ~1.8 cm without the person, so there the 1 cm bound cannot hold whatever the mask does.
// (At 160x120 or with 2 cm voxels ICP loses the orbit.)
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/exec.hpp"
#include "eval/trajectory_eval.hpp"
#include "io/movers.hpp"
#include "io/synthetic_source.hpp"
#include "kernels/recon/dynamic.hpp"
#include "kernels/scene/synthetic_room.hpp"
#include "recon/tracker_sequence.hpp"
#include "recon/volume.hpp"

using namespace seamless;

namespace {

// configs/dynamic_person.yaml's: 240 frames, the person from 1 s (frame 30) to 4.9 s (3.1 m at
// 0.8 m/s), then 3 s of empty room in which carving removes what the person left.
constexpr int kFrames = 240;
constexpr double kFps = 30.0;
constexpr float kPersonSpeed = 0.8f;
constexpr double kPersonStart = 1.0;

// The device of the runs and the image's size divisor: the GPU at full resolution where there is one.
Device device() { return cuda_available() ? Device::CUDA : Device::CPU; }
int downscale() { return device() == Device::CUDA ? 1 : 2; }

// configs/dynamic_person.yaml's scene, at the Kinect's resolution on the GPU and at half of it on the
// CPU, or at 1/k of it.
InputParams scene(bool with_movers, int k = downscale()) {
  InputParams in;
  in.source = InputSource::synthetic;
  in.synthetic.frames = kFrames;
  in.synthetic.fps = kFps;
  in.synthetic.speed_deg = 15.f;
  in.intrinsics.preset = "custom";
  in.intrinsics.fx = in.intrinsics.fy = 525.f / k;  // the Kinect's focal length in pixels
  in.intrinsics.cx = (640.f / k - 1.f) * 0.5f, in.intrinsics.cy = (480.f / k - 1.f) * 0.5f;
  in.intrinsics.width = 640 / k, in.intrinsics.height = 480 / k;
  if (with_movers) {
    MoverParams person;
    person.kind = MoverKind::person, person.path = {{-1.3f, 1.15f, 0.f}, {1.8f, 1.15f, 0.f}},
    person.speed = kPersonSpeed;
    person.start = kPersonStart;
    MoverParams ball;
    ball.kind = MoverKind::ball, ball.path = {{1.5f, 1.7f, 0.f}, {-1.2f, 1.7f, 0.f}}, ball.speed = 0.4f,
    ball.start = 0.5;
    ball.radius = 0.15f;
    in.synthetic.movers = {person, ball};
  }
  return in;
}

TrackSequenceParams params(bool dynamic, const std::string& tracker) {
  TrackSequenceParams p;
  p.tracker.kind = tracker;
  p.tracker.mode = TrackingMode::frame_to_model;
  p.volume.voxel_size = 0.01f;  // configs/dynamic_person.yaml's volume
  p.volume.truncation = 0.04f;
  p.volume.hash_buckets = 1 << 16;
  p.volume.capacity = 1 << 15;
  p.dynamic.enabled = dynamic;
  p.write_files = false;
  return p;
}

// A variant of a run: how its parameters and its volume differ from params()'s.
struct Variant {
  FreeSpaceEvidence evidence = DynamicParams{}.free_space_evidence;  // views
  float evidence_min_weight = 1.f;
  bool store_free_space = false;  // also without seen_free (which stores it itself)
};

struct Outcome {
  double ate_m = 0;  // ATE RMSE after se3 alignment (seamless eval's)
  double min_iou = 1, mean_iou = 0;
  std::vector<double> mover_recall;  // per mover (person, ball), over every frame with a mask
  int iou_frames = 0;
  std::int64_t ghost_vertices = 0;  // mesh vertices inside the person's swept volume
  double mean_fraction = 0;
  std::vector<std::pair<std::int64_t, double>> below;  // frames with IoU under 0.8, and their IoU
  // Median ms per frame of the volume's stages (allocate includes the free-space rays), of the
  // dynamic pixels (with the ground-truth tracker: the model raycast, classification, evidence),
  // the mean blocks fused per frame (the fusion's work, whatever the load), and the volume's size
  // at the end. raycast_ms: the volume's raycast after fusion (the next frame's reference; the
  // mask's own model raycast is part of dynamic_ms).
  double allocate_ms = 0, visible_ms = 0, fuse_ms = 0, dynamic_ms = 0, raycast_ms = 0, fused_blocks = 0;
  VolumeStats volume;
};

void print_below(const char* what, const Outcome& o) {
  std::printf("%s: recall per mover", what);
  for (double r : o.mover_recall) std::printf(" %.3f", r);
  std::printf("\n");
  if (o.below.empty()) return;
  std::printf("%s: %zu frames with IoU under 0.8:", what, o.below.size());
  for (const auto& [frame, iou] : o.below) std::printf(" %lld (%.2f)", static_cast<long long>(frame), iou);
  std::printf("\n");
}

// A person's capsules over the run, in the room frame.
std::vector<kernels::movers::Scene> person_track(const InputParams& in) {
  std::vector<kernels::movers::Scene> out;
  std::vector<MoverParams> person{in.synthetic.movers.at(0)};
  for (int k = 0; k < kFrames; ++k) out.push_back(pose_movers(person, k / kFps));
  return out;
}

// tracker ground_truth: the map is exactly in the room frame (up to the first pose), so the ghost
// measures fusion and carving alone; icp: the tracking error.
Outcome run(const InputParams& in, bool dynamic, const std::string& tracker = "icp", const Variant& variant = {}) {
  SyntheticSource src(in);
  TrackSequenceParams p = params(dynamic, tracker);
  p.dynamic.free_space_evidence = variant.evidence;
  p.dynamic.evidence_min_weight = variant.evidence_min_weight;
  StageTimer stages(device());
  p.volume_stages = &stages;
  std::unique_ptr<Volume> volume = make_volume(p.volume, device());  // given: with dynamic off the session makes none
  if (variant.store_free_space) volume->set_free_space_storage(true);
  TrackingSession s(p, device(), src.intrinsics(), volume.get());
  SE3 world_T_room = SE3::identity();
  Outcome o;
  RgbdFrame f;
  Trajectory est, gt;
  double fraction_sum = 0, fused_sum = 0;
  std::vector<double> dynamic_ms;
  std::vector<std::pair<std::int64_t, MaskScore>> scores;
  int n = 0;
  while (src.next(f)) {
    const FrameRecord r = s.process(f);
    EXPECT_TRUE(r.result.ok()) << "frame " << f.index << (dynamic ? " dynamic on: " : " dynamic off: ")
                               << to_string(r.result.status) << ", inliers " << r.result.inlier_ratio << ", masked "
                               << r.dynamic_fraction;
    if (n == 0) world_T_room = r.result.world_T_camera * f.ground_truth->inverse();
    fused_sum += static_cast<double>(s.volume()->stats().visible_blocks);
    est.push_back(TumPose::from_se3(f.timestamp, r.result.world_T_camera));
    gt.push_back(TumPose::from_se3(f.timestamp, *f.ground_truth));
    ++n;
    if (!dynamic || in.synthetic.movers.empty() || f.index == 0) continue;
    fraction_sum += r.dynamic_fraction;
    dynamic_ms.push_back(r.dynamic_ms);
    // Mask quality (the condition of recon/mask_score.hpp): scored by the session itself.
    if (r.mask_score) scores.push_back({f.index, *r.mask_score});
  }
  o.allocate_ms = stages.median_ms("allocate"), o.visible_ms = stages.median_ms("visible");
  o.fuse_ms = stages.median_ms("fuse"), o.dynamic_ms = median(dynamic_ms);
  o.raycast_ms = stages.median_ms("raycast");
  o.fused_blocks = fused_sum / std::max(1, n);
  o.volume = s.volume()->stats();
  const AteResult ate = compute_ate(est, gt);
  o.ate_m = ate.trans.rmse;
  if (const std::optional<MaskQuality> q = mask_quality(scores, mover_ids(in.synthetic.movers, MoverKind::person)))
    o.min_iou = q->min_iou, o.mean_iou = q->mean_iou, o.iou_frames = q->frames, o.below = q->below,
    o.mover_recall = q->mover_recall;
  o.mean_fraction = fraction_sum / std::max(1, n - 1);
  // The ghost: mesh vertices inside the person's capsules of any frame, shrunk by 2 voxels so that
  // the floor the feet stand on (a true surface within a voxel of the leg capsules' ends) does not
  // count, nor the room's own surfaces that the swinging arms reach into (the far wall): a vertex
  // within 2 voxels of the room's exact surface is the room.
  const auto track = person_track(scene(true));
  const SE3 room_T_world = world_T_room.inverse();
  const Mesh mesh = s.volume()->extract_mesh();
  const float margin = 2 * p.volume.voxel_size;
  for (const vec3& v : mesh.positions) {
    const vec3 q = room_T_world * v;
    if (std::fabs(kernels::room::room_sdf(q)) < margin) continue;
    for (const auto& sc : track)
      if (sc.count > 0 && kernels::movers::distance(sc, q) < -margin) {
        ++o.ghost_vertices;
        break;
      }
  }
  return o;
}

}  // namespace

// One test for all five runs: the numbers compare them (the person-free run is the baseline). Tens
// of minutes on 2 shared cores (under a minute on a GPU), hence "Slow" (label slow: not in
// scripts/test's CI run; run it with `ctest --test-dir build -L slow -R Dynamic` or
// build/tests/recon/test_dynamic).
TEST(Dynamic, SlowPersonWalkingThroughTheRoom) {
  // Ghost and mask on ground-truth poses (the map in the room frame exactly); tracking with ICP.
  const Outcome off = run(scene(true), false, "ground_truth"), on = run(scene(true), true, "ground_truth");
  const Outcome tracked_off = run(scene(true), false), tracked_on = run(scene(true), true),
                empty = run(scene(false), false);
  std::printf("%s, %dx%d\n", device_name(device()), 640 / downscale(), 480 / downscale());
  std::printf("ground-truth poses, dynamic off: ghost %lld vertices\n", static_cast<long long>(off.ghost_vertices));
  std::printf(
      "ground-truth poses, dynamic on:  ghost %lld vertices, IoU min %.3f mean %.3f over %d frames, masked %.2f%%\n",
      static_cast<long long>(on.ghost_vertices), on.min_iou, on.mean_iou, on.iou_frames, 100 * on.mean_fraction);
  std::printf("icp, dynamic off: ATE %.2f cm\nicp, dynamic on:  ATE %.2f cm, IoU min %.3f mean %.3f\n",
              100 * tracked_off.ate_m, 100 * tracked_on.ate_m, tracked_on.min_iou, tracked_on.mean_iou);
  std::printf("icp, no person:   ATE %.2f cm\n", 100 * empty.ate_m);
  print_below("ground-truth poses", on);
  print_below("icp", tracked_on);
  // Mask quality: IoU at least 0.8 on every frame with the person 0.5 m or more away.
  EXPECT_GT(on.iou_frames, 10);
  EXPECT_GE(on.min_iou, 0.8);
  // Ghost: with dynamic handling off the person is fused into the model where they walked.
  EXPECT_GT(off.ghost_vertices, 100);
  EXPECT_LE(static_cast<double>(on.ghost_vertices), 0.02 * static_cast<double>(off.ghost_vertices));
  // Tracking: at most 1 cm (at the Kinect's resolution: at 320x240 the tracker alone is above it,
  // see the top), and within 20% of the same path without the person.
  if (downscale() == 1) {
    EXPECT_LE(tracked_on.ate_m, 0.01);
  }
  EXPECT_LE(tracked_on.ate_m, 1.2 * empty.ate_m);
}

// Evidence of free space on the voxel-hashed volume (docs/DYNAMIC.md, "Evidence of free space"),
// the mask and the ghost on ground-truth poses: dynamic.free_space_evidence views (the default:
// the last depth maps, nothing stored in the volume), none, none with the free space stored (what
// storing it alone changes: carving no longer frees blocks), and seen_free, which stores it, at
// evidence_min_weight 1 and 2; with the volume's cost. Each run prints its row of docs/DYNAMIC.md's
// table. Half an hour on 2 shared cores.
TEST(Dynamic, SlowFreeSpaceEvidenceOnTheHashedVolume) {
  struct Row {
    const char* name;
    Variant variant;
  };
  const Row rows[] = {{"views (the default)", {}},
                      {"none", {FreeSpaceEvidence::none}},
                      {"none, free space stored", {FreeSpaceEvidence::none, 1.f, true}},
                      {"seen_free, min weight 1", {FreeSpaceEvidence::seen_free, 1.f}},
                      {"seen_free, min weight 2", {FreeSpaceEvidence::seen_free, 2.f}}};
  std::printf("%s, %dx%d, ground-truth poses, hashed volume at 1 cm\n", device_name(device()), 640 / downscale(),
              480 / downscale());
  std::vector<Outcome> out;
  for (const Row& r : rows) {
    out.push_back(run(scene(true), true, "ground_truth", r.variant));
    const Outcome& o = out.back();
    std::printf(
        "%-24s IoU min %.3f mean %.3f (%d frames, %zu under 0.8), ghost %lld, masked %.2f%%; ms per frame "
        "(median): allocate %.2f visible %.2f fuse %.2f dynamic %.2f raycast %.2f; %.0f blocks fused per frame; "
        "%lld blocks (%.0f MiB)\n",
        r.name, o.min_iou, o.mean_iou, o.iou_frames, o.below.size(), static_cast<long long>(o.ghost_vertices),
        100 * o.mean_fraction, o.allocate_ms, o.visible_ms, o.fuse_ms, o.dynamic_ms, o.raycast_ms, o.fused_blocks,
        static_cast<long long>(o.volume.allocated_blocks), o.volume.voxel_bytes / 1048576.0);
    std::fflush(stdout);
  }
  print_below("views (the default)", out[0]);
  print_below("seen_free, min weight 1", out[3]);
  const Outcome off = run(scene(true), false, "ground_truth");
  std::printf("dynamic off: ghost %lld\n", static_cast<long long>(off.ghost_vertices));
  // Storing free space alone changes the mask little (carving keeps blocks instead of freeing them;
  // the raycast finds the same surfaces), and costs blocks.
  EXPECT_NEAR(out[2].mean_iou, out[1].mean_iou, 0.02);
  EXPECT_GT(out[2].volume.allocated_blocks, 2 * out[1].volume.allocated_blocks);
  // seen_free on the stored free space and views both keep the person (seen_free dropped them
  // without the free space stored: mean IoU 0.21) and drop what lies where no ray went before (the
  // chair's seat): better than none on the worst frame and on average, and the ghost within the
  // issue's 2 % of the static pipeline's.
  for (int k : {0, 3}) {
    EXPECT_GT(out[k].min_iou, out[1].min_iou) << rows[k].name;
    EXPECT_GT(out[k].mean_iou, out[1].mean_iou) << rows[k].name;
    EXPECT_LE(static_cast<double>(out[k].ghost_vertices), 0.02 * static_cast<double>(off.ghost_vertices))
        << rows[k].name;
  }
}

// `seamless track` and `seamless run` with a tracker that builds no model of its own (the
// ground-truth poses here; a frame-to-frame tracker alike) and dynamic.enabled: the session makes
// the volume the dynamic pixels are found against (it masked nothing before, with a warning). On
// the CPU at 160x120 over the person's first 1.3 s (frames 0-69; fast enough for CI); truth: the rendered mover
// masks. The bar is that the mask is the person's: most of the person's pixels are masked (recall
// above one half) and most masked pixels are the person's (precision above one half), averaged over
// the frames where the movers cover at least 1 % of the image. Masking nothing gives recall 0.
TEST(Dynamic, AVolumeOfItsOwnForATrackerWithoutOne) {
  InputParams in = scene(true, 4);  // 160x120
  in.synthetic.frames = 70;
  SyntheticSource src(in);
  TrackSequenceParams p = params(true, "ground_truth");
  TrackingSession s(p, Device::CPU, src.intrinsics(), nullptr);
  ASSERT_NE(s.volume(), nullptr);
  RgbdFrame f;
  double recall = 0, precision = 0;
  int frames = 0;
  while (src.next(f)) {
    s.process(f);
    const std::vector<std::uint8_t> truth = f.mover_mask.to_host();
    std::vector<std::uint8_t> mine = s.dynamic_mask().to_host();
    if (mine.empty()) mine.assign(truth.size(), 0);  // no mask before the first frame with a model
    ASSERT_EQ(truth.size(), mine.size());
    std::int64_t inter = 0, truth_n = 0, mine_n = 0;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      inter += truth[i] && mine[i];
      truth_n += truth[i] != 0;
      mine_n += mine[i] != 0;
    }
    if (truth_n < static_cast<std::int64_t>(truth.size() / 100)) continue;
    recall += static_cast<double>(inter) / static_cast<double>(truth_n);
    precision += mine_n ? static_cast<double>(inter) / static_cast<double>(mine_n) : 0.0;
    ++frames;
  }
  ASSERT_GT(frames, 10);
  RecordProperty("recall", std::to_string(recall / frames));
  RecordProperty("precision", std::to_string(precision / frames));
  EXPECT_GT(recall / frames, 0.5);
  EXPECT_GT(precision / frames, 0.5);
}
