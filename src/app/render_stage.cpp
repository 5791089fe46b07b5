#include "app/render_stage.hpp"

#include <spdlog/spdlog.h>

#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_GL
#include "render/draw_list.hpp"
#include "render/headless_output.hpp"
#include "render/renderer.hpp"
#endif

namespace seamless::app {

#if SEAMLESS_HAS_GL
namespace {

class GlRunRenderer : public RunRenderer {
 public:
  explicit GlRunRenderer(RunContext& ctx)
      : ctx_(ctx),
        p_(ctx.experiment().render),
        renderer_(p_, p_.width, p_.height),
        out_(ctx.out_dir(), p_) {
    spdlog::info("rendering {}x{} {} view with {} ({})", p_.width, p_.height, p_.view, renderer_.gl_info().renderer,
                 renderer_.gl_info().version);
  }

  void set_scene(const Mesh& mesh, const SE3& scan_camera) override {
    if (p_.view != "mesh") return;
    renderer_.set_scene_mesh(mesh);
    // Look at the mesh's centre from behind and above the first scanning camera (world up is -gravity = +y).
    vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
    for (vec3 p : mesh.positions) lo = vmin(lo, p), hi = vmax(hi, p);
    vec3 target = mesh.positions.empty() ? scan_camera.t + scan_camera.rotate({0, 0, 1}) : (lo + hi) * 0.5f;
    vec3 back = normalize(scan_camera.t - target);
    vec3 eye = scan_camera.t + back * 0.5f + vec3{0.f, 0.4f, 0.f};
    camera_ = RenderCamera::look_at(eye, target, {0.f, 1.f, 0.f}, p_.fov_y, p_.width, p_.height, p_.znear, p_.zfar);
  }

  void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) override {
    if (p_.view != "kinect") return;
    renderer_.set_kinect_view(frame.rgb, frame.depth, frame.intrinsics, world_T_camera);
    camera_ = renderer_.kinect_camera();
  }

  void draw(const ParticleSolver& solver) override {
    StageScope s(ctx_.timer(), "render");
    ParticleState state = solver.download_state();
    DrawList list = make_draw_list(state, solver.rigid_frames(), 0.5f * solver.params().particle_diameter);
    renderer_.draw(list, camera_);
    out_.add(renderer_);
  }

  void finish() override {
    out_.finish();
    spdlog::info("rendered {} frames{}", out_.frames(), out_.video_open() ? " and " + out_.video_path() : "");
  }

 private:
  RunContext& ctx_;
  RenderParams p_;
  Renderer renderer_;
  HeadlessOutput out_;
  RenderCamera camera_{};
};

}  // namespace
#endif

std::unique_ptr<RunRenderer> RunRenderer::make(RunContext& ctx) {
  const RenderParams& p = ctx.experiment().render;
  if (p.mode == "none") return nullptr;
#if SEAMLESS_HAS_GL
  if (p.mode == "window") spdlog::warn("render.mode window is not wired into `seamless run` yet: rendering headless");
  return std::make_unique<GlRunRenderer>(ctx);
#else
  spdlog::warn("render.mode is {} but this build has no renderer (GL module off: apt-get install libegl-dev "
               "libgl-dev libepoxy-dev); continuing without pictures",
               p.mode);
  return nullptr;
#endif
}

}  // namespace seamless::app
