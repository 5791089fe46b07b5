#include "app/render_stage.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>

#include "core/error.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_GL
#include "io/colour_region.hpp"
#include "io/png_io.hpp"
#include "render/headless_output.hpp"
#include "render/renderer.hpp"
#if SEAMLESS_HAS_CUDA
#include "render/cuda_interop.hpp"
#endif
#if SEAMLESS_HAS_GLFW
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include "render/window.hpp"
#endif
#endif

namespace seamless::app {

std::vector<float> plane_heights(std::optional<float> floor, const std::vector<float>& support_plane) {
  std::vector<float> heights;
  if (floor) heights.push_back(*floor);
  if (!support_plane.empty()) heights.push_back(support_plane.front());
  return heights;
}

std::vector<vec4> unmeasured_planes(const std::vector<float>& heights, vec3 up) {
  std::vector<vec4> planes;
  for (float h : heights) planes.push_back({up.x, up.y, up.z, h});
  return planes;
}

SceneCamera mesh_view_camera(const Mesh& mesh, const SE3& scan_camera, const RenderParams& p) {
  vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (vec3 q : mesh.positions) lo = vmin(lo, q), hi = vmax(hi, q);
  vec3 target = mesh.positions.empty() ? scan_camera.t + scan_camera.rotate({0, 0, 1}) : (lo + hi) * 0.5f;
  if (p.target.size() == 3) target = {p.target[0], p.target[1], p.target[2]};
  const vec3 back = normalize(scan_camera.t - target);
  vec3 eye = scan_camera.t + back * 0.5f + vec3{0.f, 0.4f, 0.f};
  if (p.eye.size() == 3) eye = {p.eye[0], p.eye[1], p.eye[2]};
  return {eye, target};
}

SceneCamera orbit_camera(const SceneCamera& c, const RenderParams& p, float progress) {
  const float a = p.orbit_deg * std::clamp(progress, 0.f, 1.f) * std::numbers::pi_v<float> / 180.f;
  const vec3 r = c.eye - c.target;
  const float cs = std::cos(a), sn = std::sin(a);
  // A turn about +y by a: (x, z) -> (x cos a + z sin a, -x sin a + z cos a); a positive angle turns
  // +z towards +x (from ahead of the first camera towards its right).
  return {c.target + vec3{cs * r.x + sn * r.z, r.y, -sn * r.x + cs * r.z}, c.target};
}

// ---------------------------------------------------------------------------------------------
// Rendering during the run

#if SEAMLESS_HAS_GL
namespace {

// One frame's DrawList from the solver: its objects and its rigid frames (render's make_draw_list).
class RunDrawState {
 public:
  // Host path: the state is downloaded and kept here (the DrawList's spans point into it).
  DrawList host_list(const ParticleSolver& solver) {
    state_ = solver.download_state();
    return with_up(make_draw_list(state_, solver.objects(), solver.rigid_frames(), radius(solver)), solver);
  }
  // Device path: everything but the particles, which the interop buffer holds.
  static DrawList device_list(const ParticleSolver& solver) {
    return with_up(make_draw_list({}, {}, solver.size(), solver.objects(), solver.rigid_frames(), radius(solver)),
                   solver);
  }

 private:
  static float radius(const ParticleSolver& s) { return 0.5f * s.params().particle_diameter; }
  static DrawList with_up(DrawList d, const ParticleSolver& s) {
    d.up = s.params().up();
    return d;
  }
  ParticleState state_;
};

class GlRunRenderer : public RunRenderer {
 public:
  explicit GlRunRenderer(RunContext& ctx)
      : ctx_(ctx), p_(ctx.experiment().render), region_(input_colour_region(ctx.experiment().input)),
        renderer_(p_, p_.width, p_.height), out_(ctx.out_dir(), p_) {
    spdlog::info("rendering {}x{} {} view with {} ({})", p_.width, p_.height, enum_name(p_.view),
                 renderer_.gl_info().renderer, renderer_.gl_info().version);
#if SEAMLESS_HAS_CUDA
    // The solver's device arrays go straight into the GL buffers (no host round trip) when the GL
    // context is on the CUDA device (NVIDIA's EGL); elsewhere registration fails: host upload.
    if (ctx.device() == Device::CUDA && p_.cuda_interop) {
      try {
        interop_ = std::make_unique<CudaGlParticles>(renderer_, ctx.experiment().solver.max_particles);
        spdlog::info("render: particles reach OpenGL by CUDA interop (device to device)");
      } catch (const std::exception& e) {
        spdlog::warn("render: no CUDA-OpenGL interop with this GL context ({}); uploading from the host", e.what());
      }
    }
#endif
  }

  void set_scene(const Mesh& mesh, const SE3& scan_camera) override {
    if (p_.view != RenderView::mesh) return;
    renderer_.set_scene_mesh(mesh);
    if (have_recorded_camera_) return;  // the recorded frames set it
    mesh_camera_ = mesh_view_camera(mesh, scan_camera, p_);
    have_mesh_camera_ = true;
    set_mesh_camera(0.f);
  }

  void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) override {
    if (p_.view == RenderView::kinect) {
      renderer_.set_kinect_view(frame.rgb, frame.depth, frame.intrinsics, world_T_camera, region_);
      camera_ = renderer_.kinect_camera();
    } else if (p_.camera == RenderCameraMode::recorded) {  // the mesh seen through the recorded camera
      camera_.K = scale_intrinsics(zoom_intrinsics(frame.intrinsics, p_.zoom, p_.zoom_at), p_.width, p_.height);
      camera_.world_T_camera = world_T_camera;
      camera_.znear = p_.znear, camera_.zfar = p_.zfar;
      have_recorded_camera_ = true;
    }
  }

  void set_unmeasured_planes(const std::vector<vec4>& world_planes) override {
    renderer_.set_unmeasured_planes(world_planes);
  }

  void draw(const ParticleSolver& solver) override {
    StageScope s(ctx_.timer(), "render");
    // The orbit's progress: simulated time over the run's duration (0 at the first frame).
    const double duration = ctx_.experiment().duration;
    if (p_.orbit_deg != 0.f && have_mesh_camera_ && !have_recorded_camera_ && duration > 0.0)
      set_mesh_camera(static_cast<float>(solver.stats().time / duration));
#if SEAMLESS_HAS_CUDA
    if (interop_ && solver.device() == Device::CUDA) {
      interop_->copy_from_device(solver.device_positions(), solver.device_phases(), solver.size(),
                                 0.5f * solver.params().particle_diameter);
      renderer_.draw_device_particles(draw_state_.device_list(solver), solver.size(), camera_);
      out_.add(renderer_);
      return;
    }
#endif
    renderer_.draw(draw_state_.host_list(solver), camera_);
    out_.add(renderer_);
  }

  std::vector<std::pair<std::string, double>> gpu_passes() const override { return named(renderer_.timings()); }
  std::vector<std::pair<std::string, double>> last_gpu_passes() override { return named(renderer_.last_timings()); }

  void finish() override {
    out_.finish();
    // The last frame on its own: what a reader sees first of a run (scripts/demo prints it).
    if (out_.frames() > 0) write_png_rgb(ctx_.out_path("preview.png"), renderer_.read_frame());
    spdlog::info("rendered {} frames{}{}", out_.frames(), out_.video_open() ? " and " + out_.video_path() : "",
                 out_.frames() > 0 ? ", the last as preview.png" : "");
  }

 private:
  static std::vector<std::pair<std::string, double>> named(const std::vector<RenderTiming>& timings) {
    std::vector<std::pair<std::string, double>> out;
    for (const RenderTiming& t : timings) out.emplace_back(t.pass, t.ms);
    return out;
  }
  void set_mesh_camera(float progress) {
    const SceneCamera c = orbit_camera(mesh_camera_, p_, progress);
    camera_ = RenderCamera::look_at(c.eye, c.target, {0.f, 1.f, 0.f}, p_.fov_y, p_.width, p_.height, p_.znear, p_.zfar);
  }

  RunContext& ctx_;
  RenderParams p_;
  PixelRect region_;  // where the recorded frames hold colour (undistortion's border left out)
  Renderer renderer_;
  HeadlessOutput out_;
  RenderCamera camera_{};
  bool have_recorded_camera_ = false;
  SceneCamera mesh_camera_{};  // render.eye/target or their defaults, before the orbit
  bool have_mesh_camera_ = false;
  RunDrawState draw_state_;
#if SEAMLESS_HAS_CUDA
  std::unique_ptr<CudaGlParticles> interop_;
#endif
};

#if SEAMLESS_HAS_GLFW
// render.mode: window. The window's loop drives the run (FrameLoop::advance once a shown frame,
// unless paused) and draws the solver itself; the run's scene changes (mesh, Kinect frame) are
// kept here and handed to the window's renderer before its next frame.
class WindowRunRenderer : public RunRenderer {
 public:
  explicit WindowRunRenderer(RunContext& ctx) : ctx_(ctx), region_(input_colour_region(ctx.experiment().input)) {}

  void set_scene(const Mesh& mesh, const SE3& scan_camera) override {
    mesh_ = mesh, mesh_camera_ = scan_camera, new_mesh_ = true;
  }
  void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) override {
    rgb_ = frame.rgb.clone(Device::CPU), depth_ = frame.depth.clone(Device::CPU);
    K_ = frame.intrinsics, pose_ = world_T_camera, new_frame_ = true;
  }
  void set_unmeasured_planes(const std::vector<vec4>& world_planes) override {
    planes_ = world_planes, new_planes_ = true;
  }
  void draw(const ParticleSolver&) override {}  // the window pulls its frames
  void finish() override {}

  void run(FrameLoop& loop) override {
    const Experiment& e = ctx_.experiment();
    bool running = true;
    std::int64_t shown = 0;
    WindowCallbacks cb;
    cb.step = [&] {
      if (running && !(running = loop.advance()))
        spdlog::info("window: the run is complete; the window stays open to look around (Esc closes it)");
    };
    cb.spawn_next = [&] { loop.spawn_next(); };
    cb.on_start = [&](Renderer& r) { hand_over(r); };
    cb.before_draw = [&](Renderer& r) { hand_over(r); };
    cb.draw_list = [&] {
      StageScope s(ctx_.timer(), "render");
      ++shown;
      return draw_state_.host_list(loop.solver());
    };
    if (const int n = ctx_.window_frames(); n > 0)  // Esc before frame n-1: n frames are shown
      cb.scripted_keys = [n](int frame) {
        return frame == n - 1 ? std::vector<int>{GLFW_KEY_ESCAPE} : std::vector<int>{};
      };
    spdlog::info(
        "window: Space pause, N single step, G spawn the next object, 1-5 layers, F fluid style, "
        "V mesh/Kinect view, C orbit/fly, drag/wheel/WASDQE move, Esc quit");
    run_window(e.render, "seamless: " + e.name, cb, start_view());
    spdlog::info("window closed after {} frames{}", shown, running ? ", before the run was complete" : "");
  }

 private:
  // Orbit around the scanned mesh's centre from about where the headless mesh view looks; without
  // a mesh yet (live mode), around a point 1.5 m in front of the first camera (the origin, +z).
  WindowView start_view() const {
    WindowView v;
    v.up = {0.f, 1.f, 0.f};  // the tracker's world has gravity along -y
    v.target = {0.f, 0.f, 1.5f};
    v.distance = 2.5f;
    if (!mesh_.positions.empty()) {
      const SceneCamera c = mesh_view_camera(mesh_, mesh_camera_, ctx_.experiment().render);
      v.target = c.target, v.distance = std::max(0.5f, length(c.eye - c.target));
    }
    return v;
  }
  void hand_over(Renderer& r) {
    if (new_mesh_) r.set_scene_mesh(mesh_);
    if (new_frame_) r.set_kinect_view(rgb_, depth_, K_, pose_, region_);
    if (new_planes_) r.set_unmeasured_planes(planes_);
    new_mesh_ = new_frame_ = new_planes_ = false;
  }

  RunContext& ctx_;
  RunDrawState draw_state_;
  Mesh mesh_;
  SE3 mesh_camera_ = SE3::identity(), pose_ = SE3::identity();
  Image<uchar3> rgb_;
  Image<float> depth_;
  Intrinsics K_{};
  PixelRect region_{};
  std::vector<vec4> planes_;
  bool new_mesh_ = false, new_frame_ = false, new_planes_ = false;
};

// Why no window can be opened here, or "" when one can.
std::string no_window_reason() {
  if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY"))
    return "no display (DISPLAY and WAYLAND_DISPLAY are unset; over ssh use ssh -X, or run under xvfb-run)";
  if (!window_available())
    return "GLFW cannot connect to the display '" + std::string(std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "") +
           "'";
  return "";
}
#endif

}  // namespace
#endif

std::unique_ptr<RunRenderer> RunRenderer::make(RunContext& ctx) {
  const RenderParams& p = ctx.experiment().render;
  if (p.mode == RenderMode::none) return nullptr;
#if SEAMLESS_HAS_GL
  if (p.mode == RenderMode::window) {
#if SEAMLESS_HAS_GLFW
    const std::string why = no_window_reason();
    if (why.empty()) return std::make_unique<WindowRunRenderer>(ctx);
#else
    const std::string why = "this build has no GLFW (apt-get install libglfw3-dev, then reconfigure)";
#endif
    spdlog::warn("render.mode is window but no window can be opened: {}; rendering headless instead", why);
  }
  // What headless rendering writes is the render section's choice: say which, so that a missing
  // frames/ folder or video is never a surprise (docs/RENDERING.md).
  std::string what = "preview.png (the last frame)";
  if (p.write_frames) what += ", frames/NNNNNN.png";
  if (p.video) what += ", video.mp4";
  if (p.stage_images) what += ", stages/";
  spdlog::info(
      "rendering headless into {}: {}{}", ctx.out_dir(), what,
      p.write_frames || p.video ? "" : " (render.write_frames: true adds every frame, render.video: true a video)");
  return std::make_unique<GlRunRenderer>(ctx);
#else
  spdlog::warn(
      "render.mode is {} but this build has no renderer (GL module off: apt-get install libegl-dev "
      "libgl-dev libepoxy-dev); continuing without pictures",
      enum_name(p.mode));
  return nullptr;
#endif
}

}  // namespace seamless::app
