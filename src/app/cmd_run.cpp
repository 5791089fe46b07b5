// seamless run <config>: the whole flow from one experiment file. Stages that are not built yet
// are named in the log and skipped; nothing is faked (README, section Status).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>

#include "app/api.hpp"
#include "app/commands.hpp"
#include "app/ghost.hpp"
#include "app/pipeline.hpp"
#include "app/placement.hpp"
#include "app/render_stage.hpp"
#include "app/run_context.hpp"
#include "app/run_summary.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "io/movers.hpp"
#include "io/ply.hpp"
#include "io/trajectory.hpp"
#include "physics/particle_solver.hpp"

namespace seamless::app {

namespace {

int dry_run(const CommonOptions& o) {
  // load_experiment checks the rules across keys (Experiment::validate: placements, render.zoom, ...).
  Experiment e = load_experiment(o.config, overrides(o));
  spdlog::info("{}: valid ({} spawn entries, input {}, device {})", o.config, e.spawn.size(), enum_name(e.input.source),
               e.device);
  return 0;
}

// The horizontal planes the solver collides with besides the scan. The floor as an infinite plane at
// the scanned floor's height: parts of the floor the camera
// never saw (under and in front of the desk, say) have no scene particles, and objects would fall
// through them. Only where a floor was seen (find_horizontal_surfaces): a plane invented under a
// scan without one would stand in the air where the room is empty.
// `support_plane` adds a plane the user states: a surface the camera does not measure at all (a
// glossy table seen at a grazing angle returns no depth), which no scan can find.
std::optional<kernels::SceneSdf> scene_planes(const std::vector<float>& heights, vec3 up) {
  if (heights.empty()) return std::nullopt;
  kernels::SceneSdf sdf{};
  for (float h : heights) {
    kernels::SdfPrimitive& prim = sdf.prims[sdf.count++];
    prim.kind = kernels::kSdfHalfSpace;
    prim.a = up;
    prim.b = {h, 0.f, 0.f};
    prim.R = mat3::identity();
  }
  return sdf;
}

// The TSDF sampled over the mesh's bounds (plus 0.2 m) every half particle diameter, for
// solver.scene_collision: sdf (dissertation section 2.6.4: smoother than particle contacts).
SdfGrid scene_sdf_grid(Volume& volume, const Mesh& mesh, const Experiment& e) {
  if (mesh.positions.empty()) throw Error("scene_collision: sdf needs a scanned surface, and the scan produced none");
  vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (vec3 p : mesh.positions) lo = vmin(lo, p), hi = vmax(hi, p);
  SdfGrid g;
  g.voxel = 0.5f * e.solver.particle_diameter;
  g.origin = lo - vec3{0.2f, 0.2f, 0.2f};
  vec3 size = hi - lo + vec3{0.4f, 0.4f, 0.4f};
  g.dims = {static_cast<int>(size.x / g.voxel) + 1, static_cast<int>(size.y / g.voxel) + 1,
            static_cast<int>(size.z / g.voxel) + 1};
  g.values = volume.sample_sdf_grid(g.origin, g.dims, g.voxel);
  spdlog::info("scene SDF grid {}x{}x{} at {} m", g.dims.x, g.dims.y, g.dims.z, g.voxel);
  return g;
}

void log_escaped(const EscapedParticles& x, std::size_t dynamic) {
  if (x.total() == 0) return spdlog::info("physics: none of the {} dynamic particles left the scene", dynamic);
  spdlog::warn(
      "physics: {} of {} dynamic particles left the scene ({} below the floor, {} outside the scanned "
      "region, {} falling through or off the scan): holes in the scan (see docs/PLACEMENT.md, 'Physics on real scans')",
      x.total(), dynamic, x.below_floor, x.outside, x.falling);
}

std::vector<vec3> camera_positions(const Trajectory& tr) {
  std::vector<vec3> out;
  for (const TumPose& p : tr) out.push_back(p.se3().t);
  return out;
}

}  // namespace

RunOutputs run_experiment(RunContext& ctx, const std::string& config) {
  RunOutputs out;
  Experiment& e = ctx.experiment();
  // The rules across keys (placements, render camera and zoom, ...) were checked when the config was
  // loaded (Experiment::validate), so a malformed config costs no scan.
  auto renderer = RunRenderer::make(ctx);
  RunSummary& summary = out.summary;
  summary.command = "run", summary.config = config, summary.device = device_name(ctx.device());
  if (ctx.device() == Device::CUDA) summary.device += std::string(" (") + cuda_device_description() + ")";
  if (e.mode == ExperimentMode::live) {
    out.live = true;
    out.live_frames = live(ctx, renderer.get());
    spdlog::info("outputs in {}", ctx.out_dir());
    return out;
  }
  out.scan = scan(ctx, true);
  ScanResult& scan_result = out.scan;
  const Trajectory& traj = scan_result.tracking.trajectory;
  summary.intrinsics = scan_result.intrinsics;
  add_tracking(summary, scan_result.tracking, scan_result.unreadable, groundtruth_path(ctx));
  summary.mask_quality =
      mask_quality(scan_result.tracking.frames, mover_ids(e.input.synthetic.movers, MoverKind::person));
  if (const std::string gt = groundtruth_path(ctx); !gt.empty())
    summary.ghost_vertices =
        ghost_vertices(scan_result.mesh, e.input, traj, read_tum_trajectory(gt), 2 * e.volume.voxel_size);
  summary.online_refine = scan_result.online_refine;
  summary.seen_through = scan_result.seen_through;
  std::optional<SdfGrid> grid;
  if (e.solver.scene_collision == SceneCollision::sdf) grid = scene_sdf_grid(*scan_result.volume, scan_result.mesh, e);
  SceneParticleParams sp;
  sp.spacing = e.solver.particle_diameter;
  sp.interior_depth = e.scene_interior_depth;
  SceneParticles scene = scan_result.volume->extract_scene_particles(sp);
  std::vector<vec3> points = scene.positions.to_host();
  points.resize(static_cast<std::size_t>(scene.count));
  spdlog::info("{} scene particles at {} m spacing", points.size(), sp.spacing);
  ParticleState scene_state;
  scene_state.x = points;
  scene_state.v.assign(points.size(), vec3{0.f, 0.f, 0.f});
  scene_state.inv_mass.assign(points.size(), 0.f);
  scene_state.phase.assign(points.size(), 0u);
  write_particles_ply(ctx.out_path("scene_particles.ply"), scene_state);

  // The scene's horizontal surfaces with gravity (world -y after the tracker's gravity alignment).
  PlacementScene ps;
  ps.up = e.solver.up();
  ps.mesh = &scan_result.mesh;
  ps.surfaces = find_horizontal_surfaces(scan_result.mesh, ps.up, camera_positions(traj));
  ps.scene_points = &points;
  ps.volume = scan_result.volume.get();
  ps.trajectory = &traj;
  ps.K = scan_result.intrinsics;
  spdlog::info("scan: {}", describe_surfaces(ps.surfaces));
  summary.placements = resolve_placements(e.spawn, e.solver, ps);
  if (!summary.placements.empty() && e.output.write_config)
    write_effective_config(e, ctx.out_path("config.yaml"));  // with the resolved positions
  summary.spawns = e.spawn;

  if (renderer) {
    renderer->set_scene(scan_result.mesh, traj.empty() ? SE3::identity() : traj.front().se3());
    if (e.render.camera == RenderCameraMode::fixed && !traj.empty())
      renderer->set_kinect_frame(scan_result.first_frame, traj.front().se3());
  }
  const HorizontalSurface* floor_surface = e.floor_plane ? find_floor(ps.surfaces) : nullptr;
  const std::vector<float> heights = plane_heights(floor_height(floor_surface), e.support_plane);
  std::optional<kernels::SceneSdf> floor = scene_planes(heights, ps.up);
  // The same planes, where the recording has no depth: they hide and receive shadows.
  if (renderer) renderer->set_unmeasured_planes(unmeasured_planes(heights, ps.up));
  if (floor_surface) spdlog::info("floor plane at height {:.3f} m along -gravity", floor_surface->height);
  else if (e.floor_plane) spdlog::info("no floor plane: the scan shows no floor");
  if (!e.support_plane.empty())
    spdlog::info("support plane (config) at height {:.3f} m along -gravity", e.support_plane.front());
  const SceneBounds bounds = scene_bounds(scan_result.mesh, ps.up, floor_surface);
  summary.floor_height = bounds.floor;
  summary.surfaces = ps.surfaces;
  Replay replay{&traj, e.render.replay_start};
  const bool replaying = e.render.camera == RenderCameraMode::recorded && renderer;
  // The scene particles go to the solver on the volume's device (the host copy above is for the
  // PLY and the placement); with solver.scene_collision: sdf the TSDF replaces them.
  out.simulation = simulate(ctx, grid ? nullptr : &scene, floor ? &*floor : nullptr, renderer.get(),
                            grid ? &*grid : nullptr, replaying ? &replay : nullptr);
  const SimulationResult& sim = out.simulation;
  summary.physics = sim.stats;
  summary.escaped = count_escaped(sim.state, bounds, scan_result.mesh, e.solver.particle_diameter);
  log_escaped(*summary.escaped, sim.state.x.size());
  add_stage_medians(summary, ctx.timer());
  write_summary(ctx.out_path("summary.json"), summary);
  spdlog::info("outputs in {}", ctx.out_dir());
  out.scene_particles = std::move(points);
  return out;
}

namespace {

int run(const CommonOptions& o) {
  if (o.dry_run) return dry_run(o);
  RunContext ctx(o);
  run_experiment(ctx, o.config);
  return ctx.exit_code();
}

}  // namespace

void add_run_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<CommonOptions>();
  auto* cmd = app.add_subcommand("run", "run an experiment end to end: input, reconstruction, physics, rendering");
  add_common_options(*cmd, *o);
  add_frames_option(*cmd, *o);
  cmd->add_flag("--dry-run", o->dry_run, "validate the config and exit");
  cmd->add_option("--window-frames", o->window_frames,
                  "render.mode window: close the window after this many frames (scripted runs, tests); "
                  "the outputs hold the state reached")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([&action, o] { action = [o] { return run(*o); }; });
}

}  // namespace seamless::app
