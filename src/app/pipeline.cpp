#include "app/pipeline.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "app/ghost.hpp"
#include "app/placement.hpp"
#include "app/render_stage.hpp"
#include "app/run_summary.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/trajectory.hpp"
#include "physics/builders.hpp"
#include "physics/depth_colliders.hpp"
#include "physics/particle_io.hpp"
#include "physics/particle_solver.hpp"
#include "recon/ply.hpp"
#include "recon/refine/online_refine.hpp"

namespace seamless::app {

namespace {

// Closes the renderer's outputs (the video encoder) after the run: a failed encoder (say, one
// stopped by the same Ctrl-C) is reported, not thrown, so that the particles, trajectory, stats
// and summary that follow are still written (issue 20).
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

void log_volume(const VolumeStats& s) {
  spdlog::info(
      "volume: {} blocks of {} bytes ({:.1f} MiB voxels, {:.1f} MiB on the device), hash fill {:.1f}%, "
      "{} failed insertions, {} retries",
      s.allocated_blocks, s.bytes_per_block, s.voxel_bytes / 1048576.0, s.device_bytes / 1048576.0, 100 * s.hash_fill,
      s.failed_insertions, s.retries);
}

// The intrinsics the frames arrive with (after undistortion), in the log and in the run's folder
// (intrinsics.txt, calibration.txt's format): a run says which camera model it tracked with.
void record_intrinsics(RunContext& ctx, const FrameSource& source) {
  const Intrinsics K = source.intrinsics();
  write_calibration(ctx.out_path("intrinsics.txt"), K);
  spdlog::info("intrinsics of the frames (after any undistortion): {} (intrinsics.txt)", describe_intrinsics(K));
}
}  // namespace

ScanResult scan(RunContext& ctx, bool with_volume, StageTimer* volume_stages) {
  const Experiment& e = ctx.experiment();
  require_tracker(e.tracker.kind);
  auto source = make_source(e.input, ctx.device());
  record_intrinsics(ctx, *source);
  ScanResult r;
  if (with_volume) r.volume = make_volume(e.volume, ctx.device());

  std::int64_t total = e.frames > 0 ? e.frames : source->size().value_or(0);
  Progress progress("scan", total);
  std::int64_t n = 0;
  r.intrinsics = source->intrinsics();
  auto on_frame = [&](const RgbdFrame& frame, const FrameRecord& f) {
    ctx.timer().add(f.frame, "preprocess", f.preprocess_ms);  // as it goes: a run that fails keeps them
    ctx.timer().add(f.frame, "track", f.track_ms);
    ctx.timer().add(f.frame, "fuse", f.fuse_ms);
    ctx.timer().add(f.frame, "frame", f.frame_ms);
    if (n == 0) r.first_frame = host_copy(frame);
    progress.update(++n, to_string(f.result.status));
  };
  TrackSequenceParams tp = tracking_params(e, volume_stages);
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
  ctx.report_tracking(static_cast<std::int64_t>(r.tracking.frames.size()), r.tracking.lost_frames);
  if (r.volume) {
    log_volume(r.volume->stats());
    r.mesh = r.volume->extract_mesh();
    if (e.output.write_mesh) {
      write_ply(ctx.out_path("mesh.ply"), r.mesh);
      spdlog::info("mesh.ply: {} vertices, {} triangles", r.mesh.positions.size(), r.mesh.triangles.size());
    }
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

  ReplayFrames(const Experiment& e, Device d, const Replay& r)
      : source_(make_source(e.input, d)), traj_(*r.trajectory), start_(r.start) {
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
        replay_(replay ? std::make_unique<ReplayFrames>(e_, ctx.device(), *replay) : nullptr),
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

namespace {

// live()'s loop: one input frame per displayed frame (track, fuse, re-extract, one solver step).
class LiveLoop : public FrameLoop {
 public:
  LiveLoop(RunContext& ctx, RunRenderer* renderer, StageTimer* volume_stages)
      : ctx_(ctx), e_(ctx.experiment()), renderer_(renderer), source_(make_source(e_.input, ctx.device())),
        volume_(make_volume(e_.volume, ctx.device())),
        session_(tracking_params(e_, volume_stages), ctx.device(), source_->intrinsics(), volume_.get()),
        solver_(e_.solver, ctx.device()), total_(e_.frames > 0 ? e_.frames : source_->size().value_or(0)),
        progress_("live", total_) {
    solver_.schedule(e_.spawn);
    // An entry due with `place:` waits for the surface it is placed on (place_live).
    solver_.set_spawn_gate([this](int i, SpawnParams& sp) { return place_live(i, sp, pose_); });
    record_intrinsics(ctx, *source_);
    if (e_.output.write_trajectory) traj_ = std::make_unique<TrajectoryWriter>(ctx.out_path("trajectory.txt"));
    if (e_.refine.online)
      online_ = std::make_unique<OnlineCorrector>(e_.refine, e_.preprocess, source_->intrinsics(),
                                                  online_feedback(e_.tracker));
    sp_.spacing = e_.solver.particle_diameter;
    sp_.interior_depth = e_.scene_interior_depth;
    if (e_.solver.dynamic_colliders == DynamicColliders::depth && !e_.dynamic.enabled)
      spdlog::warn(
          "solver.dynamic_colliders: depth with dynamic.enabled false: no pixel is dynamic, so nothing "
          "from the camera collides");
    if (e_.solver.dynamic_colliders != DynamicColliders::none)
      colliders_.emplace(e_.solver.particle_diameter, e_.solver.collider_thickness, e_.solver.max_speed, ctx.device());
  }

  bool advance() override {
    if (finished_ || (total_ > 0 && static_cast<std::int64_t>(records_.size()) >= total_) || interrupted() ||
        !source_->next(frame_))
      return !(finished_ = true);
    const FrameRecord rec = session_.process(frame_);
    if (online_)
      if (std::optional<SE3> delta = online_->after_frame(frame_, rec)) session_.correct(*delta);
    const auto k = static_cast<std::int64_t>(records_.size());
    if (traj_) traj_->write(frame_.timestamp, rec.result.world_T_camera);
    poses_.push_back(TumPose::from_se3(frame_.timestamp, rec.result.world_T_camera));
    if (frame_.ground_truth) groundtruth_.push_back(TumPose::from_se3(frame_.timestamp, *frame_.ground_truth));
    const bool reextract = rec.fused && (fused_++ % e_.reextract_every) == 0;
    if (reextract) extract_scene();
    if (fused_ > 0) {
      StageScope s(ctx_.timer(), "physics");
      if (!t0_) t0_ = frame_.timestamp;
      // camera recorded: the simulation keeps the recording's time (several steps a frame);
      // otherwise one step a frame, as the dissertation's live loop.
      const double target =
          e_.render.camera == RenderCameraMode::recorded ? frame_.timestamp - *t0_ : time_ + 0.5 * e_.solver.dt;
      pose_ = rec.result.world_T_camera;
      int steps = 0;
      while (time_ + (steps + 0.5) * e_.solver.dt <= target) ++steps;
      if (colliders_ && rec.result.ok()) update_colliders(rec.result.world_T_camera, time_ + steps * e_.solver.dt);
      for (int k = 0; k < steps; ++k) {
        if (colliders_) solver_.set_collider_particles(colliders_->points(), colliders_->at(time_ + e_.solver.dt));
        solver_.step();  // spawns what is due first
        time_ += e_.solver.dt;
      }
    }
    if (renderer_) {
      renderer_->set_kinect_frame(frame_, rec.result.world_T_camera);
      // The window switches between the views (key V): it needs the mesh whatever render.view says.
      if (reextract && (e_.render.view == RenderView::mesh || e_.render.mode == RenderMode::window))
        renderer_->set_scene(volume_->extract_mesh(), rec.result.world_T_camera);
      renderer_->draw(solver_);
    }
    ctx_.timer().add(k, "preprocess", rec.preprocess_ms);  // as scan()'s rows: upload included
    ctx_.timer().add(k, "track", rec.track_ms);
    ctx_.timer().add(k, "fuse", rec.fuse_ms);
    ctx_.timer().end_frame(k);
    if (e_.output.particles_every > 0 && (k + 1) % e_.output.particles_every == 0)
      write_particles_ply(ctx_.out_path("particles_" + std::to_string(k + 1) + ".ply"), solver_.download_state());
    records_.push_back(rec);
    progress_.update(k + 1, to_string(rec.result.status));
    return true;
  }
  void spawn_next() override { solver_.spawn_next(); }
  const ParticleSolver& solver() const override { return solver_; }
  const std::vector<FrameRecord>& records() const { return records_; }

  // A frame failed: the statistics of the frames before it are written (the trajectory is as it goes).
  void finish_failed() {
    const auto n = static_cast<long long>(records_.size());
    spdlog::error("the run stopped at frame {}: tracking_stats.csv holds the {} frames before it", n, n);
    if (!e_.output.write_stats) return;
    try {
      write_tracking_stats(ctx_.out_path("tracking_stats.csv"), records_);
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
    }
  }

  void finish() {
    progress_.finish();
    if (solver_.pending_spawns())
      spdlog::warn(
          "live: {} spawn entries were never spawned (their time or their placement's surface never "
          "came)",
          solver_.pending_spawns());
    if (renderer_) finish_renderer(ctx_, *renderer_);
    if (online_) {
      traj_.reset();  // trajectory.txt complete under its name before it becomes trajectory_live.txt
      poses_ = online_refine_finish(*online_, ctx_.out_dir(), e_.output.write_trajectory);
    }
    if (e_.output.write_stats) write_tracking_stats(ctx_.out_path("tracking_stats.csv"), records_);
    ctx_.report_tracking(static_cast<std::int64_t>(records_.size()), session_.lost_frames());
    const ParticleState state = solver_.download_state();  // one download for the file and the summary
    write_particles_ply(ctx_.out_path("particles.ply"), state);
    write_objects(ctx_.out_path("objects.txt"), solver_.objects());  // for `seamless render`
    spdlog::info("live: {} frames ({} lost), median track {:.3f} ms, physics {:.3f} ms, extraction {:.3f} ms",
                 records_.size(), session_.lost_frames(), ctx_.timer().median_ms("track"),
                 ctx_.timer().median_ms("physics"), ctx_.timer().median_ms("extract"));
    log_volume(volume_->stats());
    const Mesh mesh = volume_->extract_mesh();
    if (e_.output.write_mesh) write_ply(ctx_.out_path("mesh.ply"), mesh);
    write_live_summary(mesh, state);
  }

 private:
  void extract_scene() {
    StageScope s(ctx_.timer(), "extract");
    scene_ = volume_->extract_scene_particles(sp_);
    points_stale_ = true;  // downloaded only when a placement asks (place_live)
    solver_.clear_static_particles();
    solver_.add_static_particles(scene_.positions, scene_.count);
  }

  // solver.dynamic_colliders: this frame's depth points as the solver's kinematic colliders
  // (physics/depth_colliders.hpp), spaced by the pyramid level's pixels, thickened by one particle
  // diameter per layer; depth: only the pixels the dynamic mask marks (a level pixel when any of
  // the full-resolution pixels it averages is). On the run's device, from the tracker's maps to
  // the solver (DeviceColliders).
  // frame_time: the simulation time this frame's steps end at; the steps between the last frame
  // and this one move the colliders with their estimated velocities (MovingColliders).
  void update_colliders(const SE3& world_T_camera, double frame_time) {
    StageScope s(ctx_.timer(), "colliders");
    const auto [vertices, normals] = session_.unmasked_level();
    const bool masked = e_.solver.dynamic_colliders == DynamicColliders::depth;  // else every pixel
    colliders_->update(*vertices, *normals, world_T_camera, masked ? &session_.dynamic_mask() : nullptr, frame_time);
  }

  // summary.json of a live run: as scan_then_simulate's, with the scene as it was at the end.
  void write_live_summary(const Mesh& mesh, const ParticleState& state) {
    RunSummary sum;
    sum.command = "run (live)", sum.config = e_.name, sum.device = device_name(ctx_.device());
    sum.intrinsics = source_->intrinsics();
    sum.frames_read = static_cast<std::int64_t>(records_.size());
    sum.frames_lost = session_.lost_frames();
    sum.frames_unreadable = source_->skipped_frames();
    for (const FrameRecord& r : records_) sum.frames_fused += r.fused;
    const vec3 up = -normalize(e_.solver.gravity);
    std::vector<vec3> cameras;
    for (const TumPose& p : poses_) cameras.push_back(p.se3().t);
    sum.surfaces = find_horizontal_surfaces(mesh, up, cameras);
    const SceneBounds b = scene_bounds(mesh, up, find_floor(sum.surfaces));
    sum.floor_height = b.floor;
    sum.placements = placements_;
    sum.spawns = spawns_;
    sum.physics = solver_.stats();
    sum.dynamic_masked_fraction = mean_dynamic_fraction(records_);
    if (!groundtruth_.empty())  // the source's own poses (the synthetic room's)
      sum.ghost_vertices = ghost_vertices(mesh, e_.input, poses_, groundtruth_, 2 * e_.volume.voxel_size);
    if (online_) sum.online_refine = online_->stats();
    sum.escaped = count_escaped(state, b, e_.solver.particle_diameter);
    add_stage_medians(sum, ctx_.timer());
    write_summary(ctx_.out_path("summary.json"), sum);
  }

  // A due entry with `place`: resolved against the surface scanned so far. Not yet possible (no
  // such surface, or it would start inside the scan): held back until the next re-extraction.
  bool place_live(int i, SpawnParams& sp, const SE3& pose) {
    if (!sp.place.active()) return true;
    if (tried_at_ == fused_) return false;  // nothing new since the last try
    tried_at_ = fused_;
    const Mesh mesh = volume_->extract_mesh();
    PlacementScene ps;
    ps.up = -normalize(e_.solver.gravity);
    ps.mesh = &mesh;
    ps.surfaces = find_horizontal_surfaces(mesh, ps.up, {pose.t});
    if (points_stale_) {
      points_ = scene_.positions.to_host();
      points_.resize(static_cast<std::size_t>(scene_.count));
      points_stale_ = false;
    }
    ps.scene_points = &points_;
    ps.volume = volume_.get();
    ps.trajectory = &poses_;
    ps.K = source_->intrinsics();
    SpawnParams trial = sp;
    try {
      placements_.push_back(resolve_placement(i, trial, e_.solver, ps));
    } catch (const Error& err) {
      spdlog::debug("live: placement not possible yet: {}", err.what());
      return false;
    }
    sp.position = trial.position;
    spawns_[i].position = trial.position;
    return true;
  }

  RunContext& ctx_;
  const Experiment& e_;
  RunRenderer* renderer_;
  std::unique_ptr<FrameSource> source_;
  std::unique_ptr<Volume> volume_;
  TrackingSession session_;
  ParticleSolver solver_;
  const std::int64_t total_;
  Progress progress_;
  std::unique_ptr<TrajectoryWriter> traj_;
  std::unique_ptr<OnlineCorrector> online_;  // refine.online
  SceneParticleParams sp_;
  std::vector<FrameRecord> records_;
  RgbdFrame frame_;
  std::int64_t fused_ = 0, tried_at_ = -1;
  double time_ = 0.0;
  SE3 pose_ = SE3::identity();                  // this frame's tracked pose (placements made while it steps)
  std::optional<double> t0_;                    // timestamp of the first fused frame
  std::optional<DeviceColliders> colliders_;    // solver.dynamic_colliders
  SceneParticles scene_;                        // the scene particles of the last extraction (device)
  std::vector<vec3> points_;                    // their host copy, for placement
  bool points_stale_ = false;                   // points_ is not scene_'s copy yet
  Trajectory poses_;                            // tracked so far (pixel placements)
  Trajectory groundtruth_;                      // the source's ground-truth poses of the same frames, where it has them
  std::vector<SpawnParams> spawns_ = e_.spawn;  // with the live placements resolved
  std::vector<ResolvedPlacement> placements_;
  bool finished_ = false;
};

}  // namespace

std::vector<FrameRecord> live(RunContext& ctx, RunRenderer* renderer, StageTimer* volume_stages) {
  require_tracker(ctx.experiment().tracker.kind);
  LiveLoop loop(ctx, renderer, volume_stages);
  try {
    if (renderer) renderer->run(loop);
    else
      while (loop.advance()) {
      }
  } catch (...) {
    loop.finish_failed();
    throw;
  }
  loop.finish();
  return loop.records();
}

}  // namespace seamless::app
