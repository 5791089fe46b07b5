// Rendering inside a run: the scene (mesh or the Kinect's own view) with the solver's particles,
// written as frames/NNNNNN.png and video.mp4 into the run's folder (render.mode: headless), or
// shown live in a window (render.mode: window; falls back to headless, with a message, where no
// window can be opened). Without the GL module the run says so and goes on without pictures.
//
// Also what `seamless render` needs to draw a finished run again (cmd_render.cpp): the run's
// objects.txt (cloth triangles, rigid bodies' rest shapes) next to its particles_<step>.ply.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "app/run_context.hpp"
#include "io/frame_source.hpp"
#include "physics/particle_solver.hpp"
#include "recon/volume.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_GL
#include "render/draw_list.hpp"
#endif

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
  virtual void draw(const ParticleSolver& solver) = 0;
  virtual void finish() = 0;
};

// What drawing a saved particle state needs besides positions and phases (particles_<step>.ply):
// which particles form cloth sheets and rigid bodies. Particle ids never change, so one file
// written at the end of the run serves every snapshot (objects spawned later have ids past the
// end of earlier snapshots and are left out of them).
struct RunObjects {
  struct Body {
    std::int64_t first = 0, count = 0;  // particle ids
    int spawn = -1;                     // index into the experiment's spawn list; -1: unknown (a box)
    std::vector<vec3> rest;             // body-frame offsets q, x = R q + c (Mueller et al. 2005)
  };
  std::vector<int3> cloth_triangles;  // particle ids
  std::vector<Body> bodies;
};

// From the solver now. Rest offsets are q = R^T (x - c) in the current frame (exact for the
// solver's shape matching after projection); bodies are matched to rigid spawn entries in the
// order the solver spawns them (by the step their time falls in, then list order), checked by
// particle count.
RunObjects collect_run_objects(const ParticleSolver& solver, const std::vector<SpawnParams>& spawns);
// objects.txt: text, see render_stage.cpp. Throws seamless::Error naming the file and line.
void write_run_objects(const std::string& path, const RunObjects& o);
RunObjects read_run_objects(const std::string& path);
// Reads what write_particles_ply writes (x y z vx vy vz float, phase uint; binary little endian).
ParticleState read_particles_ply(const std::string& path);
// Each body's frame in a saved state by shape matching (Mueller et al. 2005, eq. 7): c = mean of
// x, R = the rotation of A = sum (x - c) q^T (kernels::extract_rotation, warm-started from `warm`,
// which is updated; pass the previous snapshot's result). Bodies not in the state are skipped.
std::vector<RigidFrame> match_rigid_frames(const RunObjects& o, const ParticleState& s, std::vector<vec4>& warm);

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
// Throws ConfigError when render.eye or render.target is given but not as three numbers, or both
// are the same point.
void check_render_camera(const RenderParams& p);

#if SEAMLESS_HAS_GL
// Each body's surface in its body frame, from its spawn entry: a sphere of diameter size.x, the
// OBJ of shape: mesh placed as the builder voxelised it, or null (drawn as the box around its rest
// offsets) for boxes and bodies of unknown origin.
std::vector<std::shared_ptr<const BodyMesh>> body_meshes(const RunObjects& o, const std::vector<SpawnParams>& spawns,
                                                         const SolverParams& p);
// The rigid bodies in `frames` (matched to `o` by first particle id) with their meshes, or boxes
// around their rest offsets plus one particle radius.
std::vector<RigidDraw> rigid_draws(const std::vector<RigidFrame>& frames, const RunObjects& o,
                                   const std::vector<std::shared_ptr<const BodyMesh>>& meshes, float particle_radius);
// One frame's DrawList: particles (as spans into `s`, which must outlive it), the cloth sheets as
// one triangle mesh each, the rigid bodies in `frames` with their meshes (or boxes).
DrawList run_draw_list(const ParticleState& s, const std::vector<RigidFrame>& frames, const RunObjects& o,
                       const std::vector<std::shared_ptr<const BodyMesh>>& meshes, float particle_radius);
#endif

}  // namespace seamless::app
