#include "app/pipeline.hpp"

#include <spdlog/spdlog.h>

#include <cmath>

#include "core/progress.hpp"
#include "io/frame_source.hpp"
#include "app/render_stage.hpp"
#include "physics/particle_solver.hpp"
#include "recon/ply.hpp"

namespace seamless::app {

namespace {
TrackSequenceParams tracking_params(const Experiment& e) {
  TrackSequenceParams p;
  p.tracker = e.tracker;
  p.preprocess = e.preprocess;
  p.volume = e.volume;
  p.max_frames = e.frames;
  p.write_files = e.output.write_trajectory;
  return p;
}

void log_volume(const VolumeStats& s) {
  spdlog::info("volume: {} blocks of {} bytes ({:.1f} MiB voxels, {:.1f} MiB on the device), hash fill {:.1f}%, "
               "{} failed insertions, {} retries",
               s.allocated_blocks, s.bytes_per_block, s.voxel_bytes / 1048576.0, s.device_bytes / 1048576.0,
               100 * s.hash_fill, s.failed_insertions, s.retries);
}
}  // namespace

ScanResult scan(RunContext& ctx, bool with_volume) {
  const Experiment& e = ctx.experiment();
  require_tracker(e.tracker.kind);
  auto source = make_source(e.input, ctx.device());
  ScanResult r;
  if (with_volume) r.volume = make_volume(e.volume, ctx.device());

  std::int64_t total = e.frames > 0 ? e.frames : source->size().value_or(0);
  Progress progress("scan", total);
  std::int64_t n = 0;
  auto on_frame = [&](const RgbdFrame&, const FrameRecord& rec) { progress.update(++n, to_string(rec.result.status)); };
  r.tracking = track_sequence(*source, tracking_params(e), ctx.device(), ctx.out_dir(), r.volume.get(), on_frame);
  progress.finish();
  for (const FrameRecord& f : r.tracking.frames) {
    ctx.timer().add(f.frame, "preprocess", f.preprocess_ms);
    ctx.timer().add(f.frame, "track", f.track_ms);
    ctx.timer().add(f.frame, "fuse", f.fuse_ms);
    ctx.timer().add(f.frame, "frame", f.frame_ms);
  }
  spdlog::info("{} frames from {} ({} unreadable, skipped); {} lost by tracking; median track {:.3f} ms, frame {:.3f} ms",
               r.tracking.frames.size(), source->name(), source->skipped_frames(), r.tracking.lost_frames,
               r.tracking.median_track_ms, r.tracking.median_frame_ms);
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

void simulate(RunContext& ctx, const std::vector<vec3>& scene_particles, const kernels::SceneSdf* sdf,
              RunRenderer* renderer, const SdfGrid* grid) {
  const Experiment& e = ctx.experiment();
  ParticleSolver solver(e.solver, ctx.device());
  if (!scene_particles.empty()) solver.add_static_particles(scene_particles);
  if (sdf) solver.set_scene_sdf(*sdf);
  if (grid) solver.set_scene_sdf_grid(grid->values, grid->dims, grid->origin, grid->voxel);
  solver.schedule(e.spawn);  // checks the particle budget up front
  const auto steps = static_cast<std::int64_t>(std::ceil(e.duration / e.solver.dt));
  spdlog::info("simulating {:.2f} s in {} steps of {} s on {} scene particles{}{}", e.duration, steps, e.solver.dt,
               scene_particles.size(), sdf ? ", analytic SDF primitives" : "",
               grid ? ", the TSDF sampled on a grid" : "");
  const auto render_every = std::max<std::int64_t>(1, std::llround(1.0 / (e.render.fps * e.solver.dt)));
  Progress progress("simulate", steps);
  for (std::int64_t k = 0; k < steps; ++k) {
    {
      StageScope s(ctx.timer(), "physics");
      solver.step();
    }
    ctx.timer().end_frame(k);
    if (renderer && k % render_every == 0) renderer->draw(solver);
    int every = e.output.particles_every;
    if (every > 0 && (k + 1) % every == 0)
      write_particles_ply(ctx.out_path("particles_" + std::to_string(k + 1) + ".ply"), solver.download_state());
    progress.update(k + 1);
  }
  progress.finish();
  if (renderer) renderer->finish();
  write_particles_ply(ctx.out_path("particles.ply"), solver.download_state());
  write_run_objects(ctx.out_path("objects.txt"), collect_run_objects(solver, e.spawn));  // for `seamless render`
  SolverStats st = solver.stats();
  spdlog::info("physics: {} particles ({} fluid, {} cloth, {} rigid in {} bodies), {} substeps/step, median {:.3f} ms "
               "per step; neighbour overflow {} / {}",
               st.particles, st.fluid_particles, st.cloth_particles, st.rigid_particles, st.rigid_bodies, st.substeps,
               ctx.timer().median_ms("physics"), st.neighbour_overflow, st.static_neighbour_overflow);
  if (st.neighbour_overflow || st.static_neighbour_overflow)
    spdlog::warn("some particles had more neighbours than solver.max_neighbours / max_static_neighbours: raise them");
}

void live(RunContext& ctx, RunRenderer* renderer) {
  const Experiment& e = ctx.experiment();
  require_tracker(e.tracker.kind);
  auto source = make_source(e.input, ctx.device());
  auto volume = make_volume(e.volume, ctx.device());
  TrackingSession session(tracking_params(e), ctx.device(), source->intrinsics(), volume.get());
  ParticleSolver solver(e.solver, ctx.device());
  solver.schedule(e.spawn);
  std::unique_ptr<TrajectoryWriter> traj;
  if (e.output.write_trajectory) traj = std::make_unique<TrajectoryWriter>(ctx.out_path("trajectory.txt"));
  std::vector<FrameRecord> records;
  SceneParticleParams sp;
  sp.spacing = e.solver.particle_diameter;

  std::int64_t total = e.frames > 0 ? e.frames : source->size().value_or(0), fused = 0;
  Progress progress("live", total);
  RgbdFrame frame;
  while ((total == 0 || static_cast<std::int64_t>(records.size()) < total) && source->next(frame)) {
    FrameRecord rec = session.process(frame);
    std::int64_t k = static_cast<std::int64_t>(records.size());
    if (traj) traj->write(frame.timestamp, rec.result.world_T_camera);
    const bool reextract = rec.fused && (fused++ % e.reextract_every) == 0;
    if (reextract) {
      StageScope s(ctx.timer(), "extract");
      SceneParticles scene = volume->extract_scene_particles(sp);
      std::vector<vec3> points = scene.positions.to_host();
      points.resize(static_cast<std::size_t>(scene.count));
      solver.clear_static_particles();
      solver.add_static_particles(points);
    }
    if (fused > 0) {
      StageScope s(ctx.timer(), "physics");
      solver.step();
    }
    if (renderer) {
      renderer->set_kinect_frame(frame, rec.result.world_T_camera);
      if (reextract && e.render.view == "mesh") renderer->set_scene(volume->extract_mesh(), rec.result.world_T_camera);
      renderer->draw(solver);
    }
    ctx.timer().add(k, "track", rec.track_ms);
    ctx.timer().add(k, "fuse", rec.fuse_ms);
    ctx.timer().end_frame(k);
    if (e.output.particles_every > 0 && (k + 1) % e.output.particles_every == 0)
      write_particles_ply(ctx.out_path("particles_" + std::to_string(k + 1) + ".ply"), solver.download_state());
    records.push_back(rec);
    progress.update(k + 1, to_string(rec.result.status));
  }
  progress.finish();
  if (renderer) renderer->finish();
  if (e.output.write_stats) write_tracking_stats(ctx.out_path("tracking_stats.csv"), records);
  write_particles_ply(ctx.out_path("particles.ply"), solver.download_state());
  write_run_objects(ctx.out_path("objects.txt"), collect_run_objects(solver, e.spawn));  // for `seamless render`
  spdlog::info("live: {} frames ({} lost), median track {:.3f} ms, physics {:.3f} ms, extraction {:.3f} ms",
               records.size(), session.lost_frames(), ctx.timer().median_ms("track"), ctx.timer().median_ms("physics"),
               ctx.timer().median_ms("extract"));
  log_volume(volume->stats());
  if (e.output.write_mesh) write_ply(ctx.out_path("mesh.ply"), volume->extract_mesh());
}

}  // namespace seamless::app
