// seamless run <config>: the whole flow from one experiment file. Stages that are not built yet
// are named in the log and skipped; nothing is faked (README, section Status).
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "app/commands.hpp"
#include "app/pipeline.hpp"
#include "app/render_stage.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "physics/particle_solver.hpp"

namespace seamless::app {

namespace {

int dry_run(const CommonOptions& o) {
  Experiment e = load_experiment(o.config, overrides(o));
  spdlog::info("{}: valid ({} spawn entries, input {}, device {})", o.config, e.spawn.size(), e.input.source,
               e.device);
  return 0;
}

// The floor as an infinite plane: parts of the floor the camera never saw (under and in front of
// the desk, say) have no scene particles, and objects would fall through them. The plane sits at
// the height below which 2% of the scene particles lie, if at least 5% of them are within 5 cm of
// it (a floor is there); nullopt otherwise.
std::optional<kernels::SceneSdf> floor_plane(const std::vector<vec3>& points, vec3 gravity) {
  if (points.size() < 100 || length(gravity) == 0.f) return std::nullopt;
  vec3 up = -normalize(gravity);
  std::vector<float> h;
  for (vec3 p : points) h.push_back(dot(p, up));
  std::vector<float> sorted = h;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 50, sorted.end());
  float floor_h = sorted[sorted.size() / 50];
  auto near = std::count_if(h.begin(), h.end(), [&](float v) { return std::fabs(v - floor_h) < 0.05f; });
  if (near < static_cast<std::ptrdiff_t>(points.size() / 20)) return std::nullopt;
  kernels::SceneSdf sdf{};
  sdf.count = 1;
  sdf.prims[0].kind = kernels::kSdfHalfSpace;
  sdf.prims[0].a = up;
  sdf.prims[0].b = {floor_h, 0.f, 0.f};
  sdf.prims[0].R = mat3::identity();
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

int run(const CommonOptions& o) {
  if (o.dry_run) return dry_run(o);
  RunContext ctx(o);
  const Experiment& e = ctx.experiment();
  auto renderer = RunRenderer::make(ctx);
  if (e.mode == "live") {
    live(ctx, renderer.get());
    spdlog::info("outputs in {}", ctx.out_dir());
    return ctx.exit_code();
  }
  ScanResult scan_result = scan(ctx, true);
  std::optional<SdfGrid> grid;
  if (e.solver.scene_collision == "sdf") grid = scene_sdf_grid(*scan_result.volume, scan_result.mesh, e);
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
  if (renderer) {
    const Trajectory& tr = scan_result.tracking.trajectory;
    renderer->set_scene(scan_result.mesh, tr.empty() ? SE3::identity() : tr.front().se3());
  }
  std::optional<kernels::SceneSdf> floor;
  if (e.floor_plane) floor = floor_plane(points, e.solver.gravity);
  if (floor) spdlog::info("floor plane at height {:.3f} m along -gravity", floor->prims[0].b.x);
  if (grid) points.clear();  // collide with the TSDF instead of scene particles
  simulate(ctx, points, floor ? &*floor : nullptr, renderer.get(), grid ? &*grid : nullptr);
  spdlog::info("outputs in {}", ctx.out_dir());
  return ctx.exit_code();
}

}  // namespace

void add_run_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<CommonOptions>();
  auto* cmd = app.add_subcommand("run", "run an experiment end to end: input, reconstruction, physics, rendering");
  add_common_options(*cmd, *o);
  cmd->add_flag("--dry-run", o->dry_run, "validate the config and exit");
  cmd->add_option("--window-frames", o->window_frames,
                  "render.mode window: close the window after this many frames (scripted runs, tests); "
                  "the outputs hold the state reached")
      ->check(CLI::NonNegativeNumber);
  cmd->callback([&action, o] { action = [o] { return run(*o); }; });
}

}  // namespace seamless::app
