// Rendering inside a run: the scene (mesh or the Kinect's own view) with the solver's particles,
// written as frames/NNNNNN.png and video.mp4 into the run's folder (render.mode: headless).
// Without the GL module the run says so and goes on without pictures.
#pragma once
#include <memory>

#include "app/run_context.hpp"
#include "io/frame_source.hpp"
#include "physics/particle_solver.hpp"
#include "recon/volume.hpp"

namespace seamless::app {

class RunRenderer {
 public:
  // nullptr when render.mode is none, or (with a warning) when this build has no renderer.
  static std::unique_ptr<RunRenderer> make(RunContext& ctx);
  virtual ~RunRenderer() = default;
  // Mesh view: the scanned mesh, seen from a camera placed behind and above `scan_camera`.
  virtual void set_scene(const Mesh& mesh, const SE3& scan_camera) = 0;
  // Kinect view: this frame's colour and depth at its tracked pose.
  virtual void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) = 0;
  virtual void draw(const ParticleSolver& solver) = 0;
  virtual void finish() = 0;
};

}  // namespace seamless::app
