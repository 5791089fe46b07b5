// seamless render <run_dir>: draws a finished run again from what it saved: mesh.ply (mesh view)
// or the input's frames at their tracked poses (Kinect view), particles_<step>.ply, objects.txt
// (cloth triangles, rigid rest shapes) and the effective config.yaml (docs/RENDERING.md).
#include <spdlog/spdlog.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <optional>
#include <regex>

#include "app/commands.hpp"
#include "app/render_stage.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/error.hpp"
#include "io/colour_region.hpp"
#include "io/ply.hpp"
#include "io/trajectory.hpp"
#include "physics/objects.hpp"
#include "physics/particle_io.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_GL
#include "render/headless_output.hpp"
#include "render/renderer.hpp"
#endif

namespace seamless::app {

namespace fs = std::filesystem;

namespace {

struct RenderOptions {
  std::string run_dir, out, view;
  int width = 0, height = 0;
  std::vector<std::string> sets;
  bool stage_images = false, video = false, last_only = false;
};

#if SEAMLESS_HAS_GL  // everything below needs the renderer

// The saved particle states by step: particles_<step>.ply, or the final particles.ply alone.
std::map<std::int64_t, std::string> snapshots(const std::string& dir, bool last_only) {
  std::map<std::int64_t, std::string> out;
  const std::regex name(R"(particles_(\d+)\.ply)");
  for (const auto& f : fs::directory_iterator(dir)) {
    std::smatch m;
    const std::string n = f.path().filename().string();
    if (std::regex_match(n, m, name)) out[std::stoll(m[1])] = f.path().string();
  }
  const std::string last = dir + "/particles.ply";
  if ((out.empty() || last_only) && fs::exists(last)) return {{out.empty() ? 0 : out.rbegin()->first + 1, last}};
  if (out.empty())
    throw Error(dir + " holds no particles_<step>.ply nor particles.ply: is it a `seamless run` folder?");
  return out;
}

Experiment load_run_config(const RenderOptions& o) {
  const std::string cfg = o.run_dir + "/config.yaml";
  if (!fs::exists(cfg))
    throw Error(cfg + " is missing: `seamless render` needs the run's effective config (output.write_config: true)");
  Experiment e = load_experiment(cfg, o.sets);
  RenderParams& p = e.render;
  if (!o.view.empty()) enum_from_name(o.view, p.view);  // --view is checked to be a RenderView name
  if (o.width > 0) p.width = o.width;
  if (o.height > 0) p.height = o.height;
  p.stage_images = p.stage_images || o.stage_images;
  p.video = o.video;
  p.write_frames = true;
  p.mode = RenderMode::headless;
  return e;
}

// The Kinect frame shown behind each snapshot: in live mode the frame of that step (one solver
// step per frame), otherwise the scan's last frame; each at its pose in trajectory.txt.
class KinectFrames {
 public:
  KinectFrames(const Experiment& e, const std::string& run_dir)
      : live_(e.mode == ExperimentMode::live), limit_(e.frames), region_(input_colour_region(e.input)) {
    traj_ = read_tum_trajectory(run_dir + "/trajectory.txt");
    source_ = make_source(e.input, Device::CPU);
  }

  // Advances to the frame for `step` and sets it on the renderer; false if there is none.
  bool set(Renderer& r, std::int64_t step) {
    const std::int64_t want = live_ ? std::max<std::int64_t>(step - 1, 0) : -1;
    RgbdFrame f;
    while ((want < 0 || read_ < want + 1) && (limit_ <= 0 || read_ < limit_) && source_->next(f)) {
      ++read_;
      have_ = true;
      frame_ = std::move(f);
      f = RgbdFrame{};
    }
    if (!have_) return false;
    for (const TumPose& p : traj_)
      if (std::fabs(p.timestamp - frame_.timestamp) < 1e-6) {
        r.set_kinect_view(frame_.rgb, frame_.depth, frame_.intrinsics, p.se3(), region_);
        return true;
      }
    throw Error("trajectory.txt has no pose at the input's frame time " + std::to_string(frame_.timestamp) +
                ": was the run made from this config's input?");
  }

 private:
  bool live_;
  std::int64_t limit_, read_ = 0;
  PixelRect region_;  // where the frames hold colour (undistortion's border left out)
  Trajectory traj_;
  std::unique_ptr<FrameSource> source_;
  RgbdFrame frame_;
  bool have_ = false;
};

// The planes the run's solver collided with besides the scan (the floor plane, as summary.json
// records its height, and the config's support_plane), for the Kinect view's pixels without depth
// as in the run (Renderer::set_unmeasured_planes).
std::vector<vec4> run_planes(const Experiment& e, const std::string& run_dir) {
  std::optional<float> floor;
  std::ifstream f(run_dir + "/summary.json");
  if (e.floor_plane && f) {
    const nlohmann::json j = nlohmann::json::parse(f, nullptr, false);
    if (!j.is_discarded() && j.contains("floor_height") && j["floor_height"].is_number())
      floor = j["floor_height"].get<float>();
  }
  return unmeasured_planes(plane_heights(floor, e.support_plane), e.solver.up());
}

SceneCamera mesh_camera(Renderer& r, const RenderOptions& o, const RenderParams& p) {
  const std::string mesh_path = o.run_dir + "/mesh.ply", traj_path = o.run_dir + "/trajectory.txt";
  Mesh mesh;
  if (fs::exists(mesh_path)) mesh = read_mesh_ply(mesh_path);
  else spdlog::warn("{} is missing: drawing the objects without the scene", mesh_path);
  if (!mesh.triangles.empty()) r.set_scene_mesh(mesh);
  SE3 first = SE3::identity();
  if (fs::exists(traj_path)) {
    Trajectory t = read_tum_trajectory(traj_path);
    if (!t.empty()) first = t.front().se3();
  }
  return mesh_view_camera(mesh, first, p);
}

int render_run(const RenderOptions& o) {
  // A command-line argument that names nothing: bad usage (exit 2), as a missing `eval` file is.
  if (!fs::is_directory(o.run_dir)) throw UsageError("run folder '" + o.run_dir + "' does not exist");
  Experiment e = load_run_config(o);
  const RenderParams& p = e.render;
  const std::string out_dir = o.out.empty() ? o.run_dir + "/render" : o.out;
  fs::create_directories(out_dir);
  const auto states = snapshots(o.run_dir, o.last_only);
  SceneObjects objects;
  if (fs::exists(o.run_dir + "/objects.txt")) {
    objects = read_objects(o.run_dir + "/objects.txt");
  } else {
    spdlog::warn(
        "{}/objects.txt is missing (a run older than `seamless render`): cloth and rigid bodies are drawn "
        "as particles",
        o.run_dir);
    e.render.show_particles = true;
  }
  attach_body_meshes(objects, e.spawn, e.solver);
  Renderer r(p, p.width, p.height);
  spdlog::info("re-rendering {} states of {} at {}x{}, {} view, with {}", states.size(), o.run_dir, p.width, p.height,
               enum_name(p.view), r.gl_info().renderer);
  const SceneCamera scene_cam = p.view == RenderView::mesh ? mesh_camera(r, o, p) : SceneCamera{};
  std::unique_ptr<KinectFrames> kinect;
  if (p.view == RenderView::kinect) {
    kinect = std::make_unique<KinectFrames>(e, o.run_dir);
    r.set_unmeasured_planes(run_planes(e, o.run_dir));
  }
  HeadlessOutput out(out_dir, p);
  std::vector<vec4> warm;
  for (const auto& [step, path] : states) {
    if (kinect && !kinect->set(r, step)) throw Error("the run's input gives no frame for the Kinect view");
    ParticleState s = read_particles_ply(path);
    std::vector<RigidFrame> frames = rigid_frames_of_state(objects, s, warm);
    RenderCamera cam{};                // the Kinect view uses its own
    if (p.view == RenderView::mesh) {  // the orbit's progress as in the run: the state's time over the duration
      const float progress = e.duration > 0.0 ? static_cast<float>(step * e.solver.dt / e.duration) : 0.f;
      const SceneCamera c = orbit_camera(scene_cam, p, progress);
      cam = RenderCamera::look_at(c.eye, c.target, {0.f, 1.f, 0.f}, p.fov_y, p.width, p.height, p.znear, p.zfar);
    }
    DrawList list = make_draw_list(s, objects, frames, 0.5f * e.solver.particle_diameter);
    list.up = e.solver.up();
    r.draw(list, cam);
    out.add(r);
  }
  out.finish();
  spdlog::info("wrote {} frames to {}/frames{}", out.frames(), out_dir, out.video_open() ? " and a video" : "");
  return 0;
}

#else

int render_run(const RenderOptions&) {
  return not_built("render",
                   "this build has no renderer (GL module off: apt-get install libegl-dev libgl-dev "
                   "libepoxy-dev, then re-run cmake)");
}

#endif

}  // namespace

void add_render_command(CLI::App& app, std::function<int()>& action) {
  auto o = std::make_shared<RenderOptions>();
  auto* cmd = app.add_subcommand("render", "draw a finished run again from its saved states (PNG frames, video)");
  cmd->add_option("run_dir", o->run_dir, "output folder of `seamless run`")->required();
  cmd->add_option("--out", o->out, "where frames/ go (default: <run_dir>/render)");
  cmd->add_option("--view", o->view, "mesh or kinect (default: the run's render.view)")
      ->check(CLI::IsMember(enum_choices<RenderView>().values));
  cmd->add_option("--width", o->width, "frame width, pixels (default: the run's render.width)")
      ->check(CLI::Range(16, 16384));
  cmd->add_option("--height", o->height, "frame height, pixels")->check(CLI::Range(16, 16384));
  cmd->add_option("--set", o->sets, "override a key of the run's config, e.g. --set render.fluid=particles");
  cmd->add_flag("--stage-images", o->stage_images, "also write the fluid stage images");
  cmd->add_flag("--video", o->video, "encode video.mp4 (needs ffmpeg)");
  cmd->add_flag("--last", o->last_only, "only the final state (particles.ply)");
  cmd->callback([&action, o] { action = [o] { return render_run(*o); }; });
}

}  // namespace seamless::app
