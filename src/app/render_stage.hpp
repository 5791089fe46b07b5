// Rendering inside a run: the scene (mesh or the Kinect's own view) with the solver's particles,
// written as frames/NNNNNN.png and video.mp4 into the run's folder (render.mode: headless), or
// shown live in a window (render.mode: window; falls back to headless, with a message, where no
// window can be opened). Without the GL module the run says so and goes on without pictures.
//
// What is drawn comes from physics: the solver's objects and rigid frames, made into a DrawList by
// render's make_draw_list. Also the cameras that `seamless render` shares with the run.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "app/run_context.hpp"
#include "io/frame_source.hpp"
#include "physics/particle_solver.hpp"
#include "recon/volume.hpp"
#include "seamless/build_config.hpp"

namespace seamless::app {

// A run's main loop, advanced one displayed frame at a time: by a plain loop, or by the window
// front end, which pulls frames at its own pace (and may pause, single-step or stop early).
class FrameLoop {
 public:
  virtual ~FrameLoop() = default;
  // One displayed frame's worth of work (some solver steps, or one input frame); false when the
  // run has nothing left to do (then it does nothing).
  virtual bool advance() = 0;
  // The next configured spawn entry that has not been spawned yet, now (window key G).
  virtual void spawn_next() = 0;
  virtual const ParticleSolver& solver() const = 0;
};

class RunRenderer {
 public:
  // nullptr when render.mode is none, or (with a warning) when this build has no renderer.
  // render.mode window: a window when GLFW is built and a display is there, else headless.
  static std::unique_ptr<RunRenderer> make(RunContext& ctx);
  // Runs `loop` to its end (headless: every frame; the loop calls draw()) or until the window is
  // closed (window: the window draws the solver itself, draw() does nothing).
  virtual void run(FrameLoop& loop) {
    while (loop.advance()) {
    }
  }
  virtual ~RunRenderer() = default;
  // Mesh view: the scanned mesh, seen from a camera placed behind and above `scan_camera`.
  virtual void set_scene(const Mesh& mesh, const SE3& scan_camera) = 0;
  // Kinect view: this frame's colour and depth at its tracked pose.
  virtual void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) = 0;
  // Kinect view: the surfaces the camera did not measure (Renderer::set_unmeasured_planes).
  virtual void set_unmeasured_planes(const std::vector<vec4>& world_planes) = 0;
  virtual void draw(const ParticleSolver& solver) = 0;
  virtual void finish() = 0;
  // The GPU time per pass (name, ms) of the draw before the last one, from the renderer's GL timer
  // queries read a frame late (Renderer::timings); empty where there are none (the window draws on
  // its own clock).
  virtual std::vector<std::pair<std::string, double>> gpu_passes() const { return {}; }
  // The same for the last draw, waiting for the GPU to finish it (the end of a run).
  virtual std::vector<std::pair<std::string, double>> last_gpu_passes() { return {}; }
};

// The horizontal planes a scan_then_simulate run's solver collides with besides the scan: the floor
// plane (its height, where the scan found a floor) and `support_plane` (a surface the camera did
// not measure). As heights along `up`, and as the renderer takes them (up . x = height).
std::vector<float> plane_heights(std::optional<float> floor, const std::vector<float>& support_plane);
std::vector<vec4> unmeasured_planes(const std::vector<float>& heights, vec3 up);

// The camera of the mesh view: at render.eye looking at render.target where given, else looking
// at the mesh's centre from behind and above the first scanning camera (world up +y: the
// tracker's world has gravity along -y).
struct SceneCamera {
  vec3 eye, target;
};
SceneCamera mesh_view_camera(const Mesh& mesh, const SE3& scan_camera, const RenderParams& p = {});
// render.orbit_deg: the eye turned about the vertical through the target by orbit_deg * progress
// (progress 0 at the run's first frame, 1 at its last; clamped); a positive angle turns +z towards +x.
SceneCamera orbit_camera(const SceneCamera& c, const RenderParams& p, float progress);

}  // namespace seamless::app
