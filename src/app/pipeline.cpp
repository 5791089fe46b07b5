#include "app/pipeline.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "app/ghost.hpp"
#include "app/pipeline_internal.hpp"
#include "app/placement.hpp"
#include "app/render_stage.hpp"
#include "app/run_summary.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/ply.hpp"
#include "io/trajectory.hpp"
#include "physics/builders.hpp"
#include "physics/depth_colliders.hpp"
#include "physics/particle_io.hpp"
#include "physics/particle_solver.hpp"
#include "recon/refine/online_refine.hpp"
#include "recon/refine/refine.hpp"

namespace seamless::app {

namespace detail {

void finish_renderer(RunContext& ctx, RunRenderer& r) {
  try {
    r.finish();
  } catch (const std::exception& e) {
    ctx.report_output_failure(e.what());
  }
}

TrackSequenceParams tracking_params(const Experiment& e, StageTimer* volume_stages) {
  TrackSequenceParams p;
  p.volume_stages = volume_stages;
  p.tracker = e.tracker;
  p.preprocess = e.preprocess;
  p.volume = e.volume;
  p.dynamic = e.dynamic;
  if (e.solver.dynamic_colliders != DynamicColliders::none) p.keep_unmasked_level = e.solver.collider_level;
  p.max_frames = e.frames;
  p.write_files = e.output.write_trajectory;
  return p;
}

RgbdFrame host_copy(const RgbdFrame& f) {
  RgbdFrame c;
  c.index = f.index, c.timestamp = f.timestamp, c.intrinsics = f.intrinsics;
  c.accelerometer = f.accelerometer, c.ground_truth = f.ground_truth;
  c.rgb = f.rgb.clone(Device::CPU), c.depth = f.depth.clone(Device::CPU);
  return c;
}

void log_volume(const VolumeStats& s, Device d) {
  spdlog::info(
      "volume: {} blocks of {} bytes in a pool of {} ({:.1f} MiB voxels, {:.1f} MiB {} in all), hash fill {:.1f}%, "
      "{} failed insertions, {} retries",
      s.allocated_blocks, s.bytes_per_block, s.block_capacity, s.voxel_bytes / 1048576.0, s.device_bytes / 1048576.0,
      d == Device::CPU ? "of host memory" : "on the GPU", 100 * s.hash_fill, s.failed_insertions, s.retries);
}

void record_intrinsics(RunContext& ctx, const FrameSource& source) {
  const Intrinsics K = source.intrinsics();
  write_calibration(ctx.out_path("intrinsics.txt"), K);
  spdlog::info("intrinsics of the frames (after any undistortion): {} (intrinsics.txt)", describe_intrinsics(K));
}
}  // namespace detail

using namespace detail;

float seen_through_slack(const VolumeParams& v) { return v.truncation + 0.03f; }

namespace {

// refine.enabled (the offline stage): the keyframe pose graph over the tracked trajectory;
// refine_run writes the refined trajectory.txt and keeps the tracker's as trajectory_odometry.txt.
void refine_offline(RunContext& ctx, ScanResult& r) {
  const Experiment& e = ctx.experiment();
  if (e.refine.enabled && e.refine.online)
    spdlog::info("refine: refine.online refined while tracking; the offline stage (refine.enabled) is skipped");
  if (!e.refine.enabled || e.refine.online) return;
  if (interrupted()) return spdlog::warn("refine: skipped (interrupted)");
  std::vector<bool> tracked;
  for (const FrameRecord& f : r.tracking.frames) tracked.push_back(f.result.ok());
  r.tracking.trajectory =
      refine_run(e.input, r.tracking.trajectory, tracked, e.refine, e.preprocess, ctx.device(), ctx.out_dir())
          .trajectory;
}

// With refinement on, the poses change after tracking (the offline stage), or while it runs
// (refine.online: the final graph moves frames fused long before): the scene is fused in a second
// pass over the input at the final poses, so that the mesh and the scene particles are those of
// trajectory.txt. Each frame is read and preprocessed again, then fused (the trajectory tracker,
// given the poses); frames that tracking lost stay out, as they did. Costs a read and preprocess
// of every frame on top of the fusion that tracking no longer does.
void fuse_at_final_poses(RunContext& ctx, ScanResult& r, StageTimer* volume_stages) {
  const Experiment& e = ctx.experiment();
  r.volume = make_volume(e.volume, ctx.device());
  auto poses = std::make_shared<std::vector<std::optional<SE3>>>();
  std::int64_t fused = 0;
  for (std::size_t i = 0; i < r.tracking.frames.size(); ++i) {
    const bool ok = r.tracking.frames[i].result.ok();
    poses->push_back(ok ? std::optional<SE3>(r.tracking.trajectory[i].se3()) : std::nullopt);
    fused += ok ? 1 : 0;
  }
  if (interrupted()) return spdlog::warn("fusion at the refined poses skipped (interrupted): the volume is empty");
  TrackSequenceParams tp = tracking_params(e, volume_stages);
  tp.tracker.kind = "trajectory";
  tp.frame_poses = poses;  // the same frames in the same order
  tp.write_files = false;
  tp.keep_unmasked_level = -1;
  tp.max_frames = static_cast<std::int64_t>(r.tracking.frames.size());
  auto source = ctx.open_source();  // a second read: refused for frames given by the caller
  Progress progress("fuse", tp.max_frames);
  std::int64_t n = 0;
  const auto t0 = std::chrono::steady_clock::now();
  track_sequence(*source, tp, ctx.device(), ctx.out_dir(), r.volume.get(), [&](const RgbdFrame&, const FrameRecord& f) {
    ctx.timer().add(f.frame, "fuse_refined", f.frame_ms);
    progress.update(++n);
  });
  progress.finish();
  spdlog::info("fused {} of {} frames at the refined poses in {:.1f} s (a second pass over the input)", fused, n,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
}

}  // namespace

ScanResult scan(RunContext& ctx, bool with_volume, StageTimer* volume_stages) {
  const Experiment& e = ctx.experiment();
  require_tracker(e.tracker.kind);
  require_refine(e.refine);  // before tracking: a missing Ceres is not found out 150 frames later
  auto source = ctx.open_source();
  record_intrinsics(ctx, *source);
  ScanResult r;
  // Refined poses are known only after tracking: the scene is then fused afterwards (fuse_at_final_poses).
  const bool fuse_after = with_volume && (e.refine.enabled || e.refine.online);
  if (with_volume && !fuse_after) r.volume = make_volume(e.volume, ctx.device());

  // frames and input.max_frames both limit the frames read (the source applies the latter).
  std::int64_t total = source->size().value_or(0);
  if (e.frames > 0 && (total == 0 || e.frames < total)) total = e.frames;
  Progress progress("scan", total);
  std::int64_t n = 0;
  r.intrinsics = source->intrinsics();
  SeenViews seen;  // what the tracked frames saw, for the seen-through ghost
  auto on_frame = [&](const RgbdFrame& frame, const FrameRecord& f) {
    if (f.result.ok() && e.output.seen_through) seen.add(frame.depth, r.intrinsics, f.result.world_T_camera);
    ctx.timer().add(f.frame, "preprocess", f.preprocess_ms);  // as it goes: a run that fails keeps them
    ctx.timer().add(f.frame, "track", f.track_ms);
    ctx.timer().add(f.frame, "fuse", f.fuse_ms);
    ctx.timer().add(f.frame, "frame", f.frame_ms);
    if (n == 0) r.first_frame = host_copy(frame);
    progress.update(++n, "tracking " + std::string(to_string(f.result.status)));
  };
  TrackSequenceParams tp = tracking_params(e, volume_stages);
  tp.keep_model_mesh = !with_volume && e.output.seen_through;  // tracking only: the tracker's model, for the ghost
  std::unique_ptr<OnlineCorrector> online;  // refine.online: the keyframe graph solved while tracking runs
  if (e.refine.online) {
    online =
        std::make_unique<OnlineCorrector>(e.refine, e.preprocess, source->intrinsics(), online_feedback(e.tracker));
    tp.corrector = online.get();
  }
  r.tracking = track_sequence(*source, tp, ctx.device(), ctx.out_dir(), r.volume.get(), on_frame);
  if (online) {
    r.tracking.trajectory = online_refine_finish(*online, ctx.out_dir(), e.output.write_trajectory);
    r.online_refine = online->stats();
  }
  r.unreadable = source->skipped_frames();
  progress.finish();
  spdlog::info(
      "{} frames from {} ({} unreadable, skipped); {} lost by tracking; median track {:.3f} ms, frame {:.3f} ms",
      r.tracking.frames.size(), source->name(), source->skipped_frames(), r.tracking.lost_frames,
      r.tracking.median_track_ms, r.tracking.median_frame_ms);
  ctx.report_tracking(static_cast<std::int64_t>(r.tracking.frames.size()), r.tracking.lost_frames,
                      r.volume ? r.volume->stats().failed_insertions : 0);
  source.reset();  // the refinement and the fusion pass read the input again
  refine_offline(ctx, r);
  if (fuse_after) fuse_at_final_poses(ctx, r, volume_stages);
  if (r.volume) {
    log_volume(r.volume->stats(), r.volume->device());
    r.mesh = r.volume->extract_mesh(true);
    if (e.output.write_mesh) {
      write_mesh_ply(ctx.out_path("mesh.ply"), r.mesh);
      spdlog::info("mesh.ply: {} vertices, {} triangles", r.mesh.positions.size(), r.mesh.triangles.size());
    }
  }
  const Mesh* model = r.volume ? &r.mesh : (r.tracking.model_mesh ? &*r.tracking.model_mesh : nullptr);
  if (model && seen.size() > 0) {
    r.seen_through = seen_through_vertices(*model, seen, seen_through_slack(e.volume));
    spdlog::info("ghost: {} of the {} mesh's {} vertices lie where at least two of {} frames saw through them",
                 r.seen_through->vertices, r.volume ? "volume" : "tracker's model", r.seen_through->mesh_vertices,
                 r.seen_through->views);
  }
  return r;
}

namespace {

// The input frames of a replay in output order, each with its tracked pose and its time since the
// replay began: forward from replay.start; when the simulation must last longer than that and the
// recording is short enough to keep in memory, backward and forward again.
class ReplayFrames {
 public:
  static constexpr std::int64_t kMaxKept = 64;  // frames kept for playing back and forth (~2 MB each)

  ReplayFrames(RunContext& ctx, const Replay& r) : source_(ctx.open_source()), traj_(*r.trajectory), start_(r.start) {
    const auto n = static_cast<std::int64_t>(traj_.size());
    if (start_ >= n)
      throw ConfigError("render.replay_start is " + std::to_string(start_) + " but the scan tracked " +
                        std::to_string(n) + " frames");
    keep_ = n - start_ <= kMaxKept;
    for (std::int64_t k = 0; k < start_; ++k)
      if (!source_->next(frame_)) throw Error("the input ended before render.replay_start on the replay");
  }
  std::int64_t frames() const { return static_cast<std::int64_t>(traj_.size()) - start_; }

  // The next output frame; false when the replay is over (min_duration seconds reached at the end
  // of a pass, or the recording ended and is not kept).
  bool next(double min_duration, const RgbdFrame*& frame, SE3& pose, double& time) {
    if (!forward_done_) {
      const std::int64_t k = start_ + static_cast<std::int64_t>(kept_.size()) + streamed_;
      if (k < static_cast<std::int64_t>(traj_.size()) && source_->next(frame_)) {
        advance_clock(frame_.timestamp);
        pose = traj_[k].se3(), time = time_;
        if (keep_) kept_.push_back({host_copy(frame_), pose});
        else ++streamed_;
        frame = keep_ ? &kept_.back().first : &frame_;
        return true;
      }
      forward_done_ = true;
      pos_ = static_cast<std::int64_t>(kept_.size()) - 1;
    }
    if (time_ >= min_duration || kept_.size() < 2) return false;
    // Back and forth: turn at either end.
    if (pos_ + dir_ < 0 || pos_ + dir_ >= static_cast<std::int64_t>(kept_.size())) dir_ = -dir_;
    pos_ += dir_;
    const auto& [f, p] = kept_[pos_];
    advance_clock(f.timestamp);
    frame = &f, pose = p, time = time_;
    return true;
  }

 private:
  // Time runs forward by the recording's frame interval whichever way the frames are played.
  void advance_clock(double timestamp) {
    if (have_last_) time_ += std::fabs(timestamp - last_stamp_);
    last_stamp_ = timestamp, have_last_ = true;
  }

  std::unique_ptr<FrameSource> source_;
  const Trajectory& traj_;
  std::int64_t start_ = 0, streamed_ = 0, pos_ = 0, dir_ = 1;
  bool keep_ = false, forward_done_ = false, have_last_ = false;
  RgbdFrame frame_;
  std::vector<std::pair<RgbdFrame, SE3>> kept_;
  double time_ = 0.0, last_stamp_ = 0.0;
};

// simulate()'s loop: render_every solver steps per displayed frame, or with a replay the steps up
// to the next replayed frame's time.
class SimulationLoop : public FrameLoop {
 public:
  SimulationLoop(RunContext& ctx, ParticleSolver& solver, RunRenderer* renderer, const Replay* replay)
      : ctx_(ctx), e_(ctx.experiment()), solver_(solver), renderer_(renderer),
        steps_(static_cast<std::int64_t>(std::ceil(e_.duration / e_.solver.dt))),
        render_every_(std::max<std::int64_t>(1, std::llround(1.0 / (e_.render.fps * e_.solver.dt)))),
        replay_(replay ? std::make_unique<ReplayFrames>(ctx, *replay) : nullptr),
        progress_(replay_ ? "replay" : "simulate", replay_ ? replay_->frames() : steps_, true,
                  replay_ ? "fps" : "steps/s") {}

  std::int64_t steps() const { return steps_; }
  std::int64_t done_steps() const { return k_; }
  bool complete() const { return replay_ ? replay_done_ : k_ >= steps_; }
  bool advance() override {
    if (replay_) return advance_replay();
    for (std::int64_t i = 0; i < render_every_ && k_ < steps_ && !interrupted(); ++i) step();
    return k_ < steps_ && !interrupted();
  }
  void spawn_next() override { solver_.spawn_next(); }
  const ParticleSolver& solver() const override { return solver_; }
  void finish() { progress_.finish(); }

 private:
  bool advance_replay() {
    const RgbdFrame* frame = nullptr;
    SE3 pose;
    double t = 0.0;
    if (replay_done_ || interrupted() || !replay_->next(e_.duration, frame, pose, t)) return !(replay_done_ = true);
    while (time_ + 0.5 * e_.solver.dt <= t) step();
    if (renderer_) {
      renderer_->set_kinect_frame(*frame, pose);
      renderer_->draw(solver_);
    }
    progress_.update(++replayed_);
    return true;
  }

  void step() {
    {
      StageScope s(ctx_.timer(), "physics");
      solver_.step();  // spawns what is due first
      time_ += e_.solver.dt;
    }
    ctx_.timer().end_frame(k_);
    if (renderer_ && !replay_ && k_ % render_every_ == 0) renderer_->draw(solver_);
    const int every = e_.output.particles_every;
    if (every > 0 && (k_ + 1) % every == 0)
      write_particles_ply(ctx_.out_path("particles_" + std::to_string(k_ + 1) + ".ply"), solver_.download_state());
    ++k_;
    if (!replay_) progress_.update(k_);
  }

  RunContext& ctx_;
  const Experiment& e_;
  ParticleSolver& solver_;
  RunRenderer* renderer_;
  const std::int64_t steps_, render_every_;
  std::unique_ptr<ReplayFrames> replay_;
  Progress progress_;
  std::int64_t k_ = 0, replayed_ = 0;
  bool replay_done_ = false;
  double time_ = 0.0;  // accumulated like the solver's clock (the replay's steps follow it)
};

}  // namespace

SimulationResult simulate(RunContext& ctx, const SceneParticles* scene_particles, const kernels::SceneSdf* sdf,
                          RunRenderer* renderer, const SdfGrid* grid, const Replay* replay) {
  const Experiment& e = ctx.experiment();
  ParticleSolver solver(e.solver, ctx.device());
  const std::int64_t n_scene = scene_particles ? scene_particles->count : 0;
  if (n_scene > 0) solver.add_static_particles(scene_particles->positions, n_scene);
  if (sdf) solver.set_scene_sdf(*sdf);
  if (grid) solver.set_scene_sdf_grid(grid->values, grid->dims, grid->origin, grid->voxel);
  solver.schedule(e.spawn);  // checks the particle budget up front
  SimulationLoop loop(ctx, solver, renderer, replay);
  if (replay)
    spdlog::info(
        "replaying input frames {}..{} from their tracked poses, simulating in the recording's time "
        "(at least {:.2f} s) in steps of {} s on {} scene particles{}{}",
        replay->start, replay->trajectory->size() - 1, e.duration, e.solver.dt, n_scene,
        sdf ? ", analytic SDF primitives" : "", grid ? ", the TSDF sampled on a grid" : "");
  else
    spdlog::info("simulating {:.2f} s in {} steps of {} s on {} scene particles{}{}", e.duration, loop.steps(),
                 e.solver.dt, n_scene, sdf ? ", analytic SDF primitives" : "",
                 grid ? ", the TSDF sampled on a grid" : "");
  if (renderer) renderer->run(loop);
  else
    while (loop.advance()) {
    }
  loop.finish();
  if (!loop.complete() && replay)
    spdlog::warn("stopped after {} steps (window closed or interrupted): the outputs hold the state reached",
                 loop.done_steps());
  else if (!loop.complete())
    spdlog::warn("stopped after {} of {} steps (window closed or interrupted): the outputs hold the state reached",
                 loop.done_steps(), loop.steps());
  if (renderer) finish_renderer(ctx, *renderer);
  SimulationResult result{solver.download_state(), solver.stats()};
  write_particles_ply(ctx.out_path("particles.ply"), result.state);
  write_objects(ctx.out_path("objects.txt"), solver.objects());  // for `seamless render`
  SolverStats st = solver.stats();
  spdlog::info(
      "physics: {} particles ({} fluid, {} cloth, {} rigid in {} bodies), {} substeps/step, median {:.3f} ms "
      "per step; neighbour overflow {} / {}",
      st.particles, st.fluid_particles, st.cloth_particles, st.rigid_particles, st.rigid_bodies, st.substeps,
      ctx.timer().median_ms("physics"), st.neighbour_overflow, st.static_neighbour_overflow);
  if (st.neighbour_overflow || st.static_neighbour_overflow)
    spdlog::warn("some particles had more neighbours than solver.max_neighbours / max_static_neighbours: raise them");
  return result;
}

}  // namespace seamless::app
