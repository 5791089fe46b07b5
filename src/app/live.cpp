// live(): the AR loop of `mode: live` (a camera frame tracked and fused, the scene particles
// re-extracted, the dynamic colliders, one solver step and the Kinect view a frame). The scan and
// the scan-then-simulate path are in pipeline.cpp.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "app/ghost.hpp"
#include "app/pipeline.hpp"
#include "app/pipeline_internal.hpp"
#include "app/placement.hpp"
#include "app/render_stage.hpp"
#include "app/run_summary.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/movers.hpp"
#include "io/ply.hpp"
#include "io/trajectory.hpp"
#include "physics/builders.hpp"
#include "physics/depth_colliders.hpp"
#include "physics/particle_io.hpp"
#include "physics/particle_solver.hpp"
#include "recon/refine/online_refine.hpp"

namespace seamless::app {

using namespace detail;

namespace {

// A particle inside a seen person for more than this many frames in a row rests inside
// (dynamic.inside_people): the colliders push a particle they reach out within the steps of one
// frame, so two frames in a row already mean they did not; one more absorbs a frame whose mask or
// depth flickers. A leg swinging at 2-3 m/s passes a particle in 2-3 frames at 30 Hz (a leg and a
// particle, ~0.15 m), so a body passing through particles without colliders counts only where it
// slows down or stands: a planted foot, a person standing.
constexpr int kInsideRestFrames = 3;

// The tracker's parameters, keeping the collider level's maps before the mask whenever there is a
// mask: the inside-people check reads them with the colliders off as well.
TrackSequenceParams live_tracking_params(const Experiment& e, StageTimer* volume_stages) {
  TrackSequenceParams p = tracking_params(e, volume_stages);
  if (e.dynamic.enabled) p.keep_unmasked_level = e.solver.collider_level;
  return p;
}

// live()'s loop: one input frame per displayed frame (track, fuse, re-extract, one solver step).
class LiveLoop : public FrameLoop {
 public:
  LiveLoop(RunContext& ctx, RunRenderer* renderer, StageTimer* volume_stages)
      : ctx_(ctx), e_(ctx.experiment()), renderer_(renderer), source_(ctx.open_source()),
        volume_(make_volume(e_.volume, ctx.device())),
        session_(live_tracking_params(e_, volume_stages), ctx.device(), source_->intrinsics(), volume_.get()),
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
    // The check's margin is one particle radius: a particle whose centre is more than a radius
    // behind the seen surface lies wholly behind it, while one touching it from outside has its
    // centre in front (a contact keeps it a diameter from the collider points on the surface). The
    // radius also covers the depth on the particle's ray differing from its level pixel's (a
    // 160x120 level pixel is ~1.5 cm wide at 2 m) and the sensor's noise there (about 1 cm).
    const float radius = 0.5f * e_.solver.particle_diameter;
    if (e_.dynamic.enabled && e_.solver.collider_thickness > radius)
      inside_.emplace(radius, e_.solver.collider_thickness, kInsideRestFrames, ctx.device());
  }

  bool advance() override {
    if (finished_ || (total_ > 0 && static_cast<std::int64_t>(records_.size()) >= total_) || interrupted() ||
        !source_->next(frame_))
      return !(finished_ = true);
    const FrameRecord rec = session_.process(frame_);
    if (e_.dynamic.write_masks) write_dynamic_mask(ctx_.out_dir(), frame_.index, session_);
    if (online_)
      if (std::optional<SE3> delta = online_->after_frame(frame_, rec)) session_.correct(*delta);
    const auto k = static_cast<std::int64_t>(records_.size());
    if (traj_) traj_->write(frame_.timestamp, rec.result.world_T_camera);
    poses_.push_back(TumPose::from_se3(frame_.timestamp, rec.result.world_T_camera));
    if (rec.result.ok() && e_.output.seen_through)
      seen_.add(frame_.depth, source_->intrinsics(), rec.result.world_T_camera);
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
      if (inside_ && rec.result.ok() && session_.has_unmasked_level()) check_inside(rec.result.world_T_camera, k);
    }
    if (renderer_) {
      {
        StageScope s(ctx_.timer(), "render");  // the recorded frame's upload is the render's work
        renderer_->set_kinect_frame(frame_, rec.result.world_T_camera);
      }
      // The window switches between the views (key V): it needs the mesh whatever render.view says.
      if (reextract && (e_.render.view == RenderView::mesh || e_.render.mode == RenderMode::window))
        renderer_->set_scene(volume_->extract_mesh(), rec.result.world_T_camera);
      renderer_->draw(solver_);
      // The previous frame's GPU time, pass by pass (GL timer queries, read a frame late so that the
      // host does not wait for the GPU: Renderer::timings): "render" is the host's side.
      if (k > 0) add_gpu_passes(k - 1, renderer_->gpu_passes());
    }
    ctx_.timer().add(k, "preprocess", rec.preprocess_ms);  // as scan()'s rows: upload included
    ctx_.timer().add(k, "track", rec.track_ms);
    ctx_.timer().add(k, "fuse", rec.fuse_ms);
    ctx_.timer().end_frame(k);
    if (e_.output.particles_every > 0 && (k + 1) % e_.output.particles_every == 0)
      write_particles_ply(ctx_.out_path("particles_" + std::to_string(k + 1) + ".ply"), solver_.download_state());
    records_.push_back(rec);
    progress_.update(k + 1, "tracking " + std::string(to_string(rec.result.status)));
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
    if (renderer_ && !records_.empty())
      add_gpu_passes(static_cast<std::int64_t>(records_.size()) - 1, renderer_->last_gpu_passes());
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
    if (inside_) {
      const InsidePeopleStats& in = inside_->stats();
      spdlog::info(
          "live: particles inside people: at most {} in a frame; resting (inside > {} frames in a row) in {} of {} "
          "frames checked, at most {}",
          in.max_inside, in.rest_frames, in.frames_resting, in.frames_checked, in.max_resting);
    }
    log_volume(volume_->stats(), volume_->device());
    const Mesh mesh = volume_->extract_mesh();
    if (e_.output.write_mesh) write_mesh_ply(ctx_.out_path("mesh.ply"), mesh);
    write_live_summary(mesh, state);
  }

 private:
  void add_gpu_passes(std::int64_t k, const std::vector<std::pair<std::string, double>>& passes) {
    double gpu_ms = 0.0;
    for (const auto& [pass, ms] : passes) ctx_.timer().add(k, "gl_" + pass, ms), gpu_ms += ms;
    if (!passes.empty()) ctx_.timer().add(k, "render_gpu", gpu_ms);
  }

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
  // and this one move the colliders with their estimated velocities.
  void update_colliders(const SE3& world_T_camera, double frame_time) {
    StageScope s(ctx_.timer(), "colliders");
    const auto [vertices, normals] = session_.unmasked_level();
    const bool masked = e_.solver.dynamic_colliders == DynamicColliders::depth;  // else every pixel
    colliders_->update(*vertices, *normals, world_T_camera, masked ? &session_.dynamic_mask() : nullptr, frame_time);
  }

  // dynamic.inside_people: after this frame's physics, the particles inside the people it sees
  // (physics/depth_colliders.hpp, InsidePeopleCheck), on the run's device from the solver's and
  // the tracker's buffers: positions in id order (the ids a particle keeps from frame to frame), the
  // full-resolution dynamic mask and the collider level's vertices before masking.
  void check_inside(const SE3& world_T_camera, std::int64_t k) {
    StageScope s(ctx_.timer(), "inside_check");
    const kernels::InsideCount c =
        inside_->check(solver_.device_positions(), solver_.size(), world_T_camera, source_->intrinsics(),
                       session_.dynamic_mask(), *session_.unmasked_level().first, k);
    if (c.resting > 0) spdlog::debug("live: frame {}: {} particles inside people, {} resting", k, c.inside, c.resting);
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
    const vec3 up = e_.solver.up();
    std::vector<vec3> cameras;
    for (const TumPose& p : poses_) cameras.push_back(p.se3().t);
    sum.surfaces = find_horizontal_surfaces(mesh, up, cameras);
    const SceneBounds b = scene_bounds(mesh, up, find_floor(sum.surfaces));
    sum.floor_height = b.floor;
    sum.placements = placements_;
    sum.spawns = spawns_;
    sum.physics = solver_.stats();
    sum.dynamic_masked_fraction = mean_dynamic_fraction(records_);
    if (inside_) sum.inside_people = inside_->stats();
    sum.mask_quality = mask_quality(records_, mover_ids(e_.input.synthetic.movers, MoverKind::person));
    if (!groundtruth_.empty())  // the source's own poses (the synthetic room's)
      sum.ghost_vertices = ghost_vertices(mesh, e_.input, poses_, groundtruth_, 2 * e_.volume.voxel_size);
    if (seen_.size() > 0) sum.seen_through = seen_through_vertices(mesh, seen_, seen_through_slack(e_.volume));
    if (online_) sum.online_refine = online_->stats();
    sum.escaped = count_escaped(state, b, mesh, e_.solver.particle_diameter);
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
    ps.up = e_.solver.up();
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
  std::optional<InsidePeopleCheck> inside_;     // dynamic.enabled: dynamic.inside_people of summary.json
  SceneParticles scene_;                        // the scene particles of the last extraction (device)
  std::vector<vec3> points_;                    // their host copy, for placement
  bool points_stale_ = false;                   // points_ is not scene_'s copy yet
  Trajectory poses_;                            // tracked so far (pixel placements)
  Trajectory groundtruth_;                      // the source's ground-truth poses of the same frames, where it has them
  SeenViews seen_;                              // what the tracked frames saw (the seen-through ghost)
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
