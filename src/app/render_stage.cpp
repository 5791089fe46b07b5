#include "app/render_stage.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/error.hpp"
#include "kernels/physics/particle_math.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_GL
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

// ---------------------------------------------------------------------------------------------
// objects.txt and particle states

namespace {

// Rigid spawn entries in the order the solver creates their bodies: by the step whose start time
// first reaches the entry's time (ParticleSolver spawns pending entries at the start of a step,
// in list order), then by list order.
std::vector<int> rigid_spawn_order(const std::vector<SpawnParams>& spawns, float dt) {
  std::vector<int> idx;
  for (int i = 0; i < static_cast<int>(spawns.size()); ++i)
    if (spawns[i].kind == "rigid") idx.push_back(i);
  auto step_of = [&](int i) { return std::max(0.0, std::ceil((spawns[i].time - 1e-9) / dt)); };
  std::stable_sort(idx.begin(), idx.end(), [&](int a, int b) { return step_of(a) < step_of(b); });
  return idx;
}

}  // namespace

RunObjects collect_run_objects(const ParticleSolver& solver, const std::vector<SpawnParams>& spawns) {
  RunObjects o;
  o.cloth_triangles = solver.cloth_triangles();
  const ParticleState s = solver.download_state();
  const std::vector<RigidFrame> frames = solver.rigid_frames();
  const std::vector<int> order = rigid_spawn_order(spawns, solver.params().dt);
  for (std::size_t b = 0; b < frames.size(); ++b) {
    const RigidFrame& f = frames[b];
    RunObjects::Body body;
    body.first = f.first, body.count = f.count;
    const mat3 Rt = transpose(kernels::quat_to_mat(f.rotation));
    for (std::int64_t i = f.first; i < f.first + f.count; ++i) body.rest.push_back(Rt * (s.x[i] - f.centre));
    if (b < order.size() && make_rigid(spawns[order[b]], solver.params()).size() == f.count) body.spawn = order[b];
    o.bodies.push_back(std::move(body));
  }
  return o;
}

// Format (text, one record a line):
//   # comment
//   cloth_triangles <n>      followed by n lines "a b c" (particle ids)
//   body <first> <count> <spawn>   followed by count lines "qx qy qz" (rest offsets, metres)
void write_run_objects(const std::string& path, const RunObjects& o) {
  std::ofstream out(path);
  if (!out) throw Error("cannot write '" + path + "'; check that the folder exists and is writable");
  out << "# seamless run objects: cloth triangles and rigid bodies in particle ids (docs/RENDERING.md)\n";
  out << "cloth_triangles " << o.cloth_triangles.size() << "\n";
  for (const int3& t : o.cloth_triangles) out << t.x << ' ' << t.y << ' ' << t.z << '\n';
  out.precision(9);
  for (const RunObjects::Body& b : o.bodies) {
    out << "body " << b.first << ' ' << b.count << ' ' << b.spawn << '\n';
    for (const vec3& q : b.rest) out << q.x << ' ' << q.y << ' ' << q.z << '\n';
  }
  if (!out) throw Error("writing '" + path + "' failed (disk full?)");
}

RunObjects read_run_objects(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot open '" + path + "' (written by `seamless run` since the renderer's issue 7)");
  RunObjects o;
  std::string line;
  int lineno = 0;
  auto next = [&](const char* what) -> std::istringstream {
    while (std::getline(in, line)) {
      ++lineno;
      if (!line.empty() && line[0] != '#') return std::istringstream(line);
    }
    throw Error(path + ": ends early, expected " + what);
  };
  auto bad = [&](const char* what) { return Error(path + ":" + std::to_string(lineno) + ": expected " + what); };
  while (true) {
    std::string tag;
    std::istringstream ls;
    try { ls = next("a record"); } catch (const Error&) { break; }
    ls >> tag;
    if (tag == "cloth_triangles") {
      std::int64_t n = -1;
      if (!(ls >> n) || n < 0) throw bad("cloth_triangles <count>");
      for (std::int64_t i = 0; i < n; ++i) {
        int3 t{};
        if (!(next("a triangle") >> t.x >> t.y >> t.z)) throw bad("three particle ids");
        o.cloth_triangles.push_back(t);
      }
    } else if (tag == "body") {
      RunObjects::Body b;
      if (!(ls >> b.first >> b.count >> b.spawn) || b.first < 0 || b.count < 1) throw bad("body <first> <count> <spawn>");
      for (std::int64_t i = 0; i < b.count; ++i) {
        vec3 q{};
        if (!(next("a rest offset") >> q.x >> q.y >> q.z)) throw bad("three rest offset coordinates");
        b.rest.push_back(q);
      }
      o.bodies.push_back(std::move(b));
    } else {
      throw bad("'cloth_triangles' or 'body'");
    }
  }
  return o;
}

ParticleState read_particles_ply(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error("cannot open particle file '" + path + "'");
  std::string line, header;
  std::int64_t n = -1;
  while (std::getline(in, line) && line != "end_header") {
    header += line + "\n";
    if (line.rfind("element vertex ", 0) == 0) n = std::stoll(line.substr(15));
  }
  const char* expected = "property float x\nproperty float y\nproperty float z\nproperty float vx\nproperty float vy\n"
                         "property float vz\nproperty uint phase\n";
  if (n < 0 || header.find("format binary_little_endian") == std::string::npos || header.find(expected) == std::string::npos)
    throw Error("'" + path + "' is not a particle file of `seamless run` (binary PLY with x y z vx vy vz phase)");
  std::vector<char> buf(static_cast<std::size_t>(n) * 28);
  if (!in.read(buf.data(), static_cast<std::streamsize>(buf.size())))
    throw Error("'" + path + "' is cut short: its header promises " + std::to_string(n) + " particles");
  ParticleState s;
  s.x.resize(n), s.v.resize(n), s.phase.resize(n), s.inv_mass.assign(n, 1.f);
  for (std::int64_t i = 0; i < n; ++i) {
    float f[6];
    std::memcpy(f, &buf[i * 28], 24);
    std::memcpy(&s.phase[i], &buf[i * 28 + 24], 4);
    s.x[i] = {f[0], f[1], f[2]}, s.v[i] = {f[3], f[4], f[5]};
  }
  return s;
}

std::vector<RigidFrame> match_rigid_frames(const RunObjects& o, const ParticleState& s, std::vector<vec4>& warm) {
  warm.resize(o.bodies.size(), vec4{0.f, 0.f, 0.f, 1.f});
  std::vector<RigidFrame> out;
  for (std::size_t b = 0; b < o.bodies.size(); ++b) {
    const RunObjects::Body& body = o.bodies[b];
    if (body.first + body.count > static_cast<std::int64_t>(s.x.size())) continue;  // not spawned yet
    vec3 c{0.f, 0.f, 0.f};
    for (std::int64_t i = 0; i < body.count; ++i) c += s.x[body.first + i];
    c = c / static_cast<float>(body.count);
    mat3 A = mat3::zero();
    for (std::int64_t i = 0; i < body.count; ++i) A = A + outer(s.x[body.first + i] - c, body.rest[i]);
    // 64 iterations: enough from identity for any rotation (each turns by the full residual angle).
    warm[b] = kernels::extract_rotation(A, warm[b], 64);
    out.push_back({c, warm[b], body.first, body.count});
  }
  return out;
}

void check_render_camera(const RenderParams& p) {
  for (const auto& [key, v] : {std::pair{"eye", &p.eye}, std::pair{"target", &p.target}})
    if (!v->empty() && v->size() != 3)
      throw ConfigError(std::string("render.") + key + ": expected [x, y, z] (three numbers, world metres), got " +
                        std::to_string(v->size()));
  if (p.eye.size() == 3 && p.target.size() == 3 && p.eye == p.target)
    throw ConfigError("render.eye and render.target are the same point: the camera would look nowhere");
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
  const float a = p.orbit_deg * std::clamp(progress, 0.f, 1.f) * kernels::kPi / 180.f;
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

// UV sphere with outward normals, 16 rings of 32 segments (smooth at the frame sizes used).
std::shared_ptr<const BodyMesh> sphere_mesh(float r) {
  auto m = std::make_shared<BodyMesh>();
  const int rings = 16, segs = 32;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= segs; ++j) {
      const float th = kernels::kPi * i / rings, ph = 2.f * kernels::kPi * j / segs;
      const vec3 n{std::sin(th) * std::cos(ph), std::cos(th), std::sin(th) * std::sin(ph)};
      m->positions.push_back(n * r), m->normals.push_back(n);
    }
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < segs; ++j) {
      const int a = i * (segs + 1) + j, b = a + segs + 1;
      m->triangles.push_back({a, a + 1, b}), m->triangles.push_back({a + 1, b + 1, b});
    }
  return m;
}

// The OBJ of a `shape: mesh` body in its body frame. The builder centres the OBJ on its bounding
// box, scales it to fit s.size and voxelises it (voxelize_obj); the rest offsets are the voxel
// centres minus their mean, so the body frame's origin is that mean in the scaled OBJ's frame.
std::shared_ptr<const BodyMesh> obj_body_mesh(const SpawnParams& s, const SolverParams& p) {
  std::ifstream in(s.mesh);
  if (!in) return nullptr;
  auto m = std::make_shared<BodyMesh>();
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::string tag, tok;
    ls >> tag;
    if (tag == "v") {
      vec3 v{};
      ls >> v.x >> v.y >> v.z;
      m->positions.push_back(v);
    } else if (tag == "f") {
      std::vector<int> f;
      const int nv = static_cast<int>(m->positions.size());
      while (ls >> tok) f.push_back(std::stoi(tok.substr(0, tok.find('/'))));
      for (int& i : f) i = i < 0 ? nv + i : i - 1;
      for (std::size_t k = 2; k < f.size(); ++k) m->triangles.push_back({f[0], f[k - 1], f[k]});
    }
  }
  if (m->positions.empty() || m->triangles.empty()) return nullptr;
  vec3 lo = m->positions[0], hi = lo;
  for (vec3 v : m->positions) lo = vmin(lo, v), hi = vmax(hi, v);
  const vec3 ext = hi - lo, mid = (lo + hi) * 0.5f;
  const float scale = std::min({s.size.x / std::max(ext.x, 1e-9f), s.size.y / std::max(ext.y, 1e-9f),
                                s.size.z / std::max(ext.z, 1e-9f)});
  vec3 mean{0.f, 0.f, 0.f};
  const std::vector<vec3> cells = voxelize_obj(s.mesh, p.particle_diameter, s.size);
  for (vec3 c : cells) mean += c;
  if (!cells.empty()) mean = mean / static_cast<float>(cells.size());
  for (vec3& v : m->positions) v = (v - mid) * scale - mean;
  m->normals = vertex_normals(m->positions, m->triangles);
  return m;
}

}  // namespace

std::vector<std::shared_ptr<const BodyMesh>> body_meshes(const RunObjects& o, const std::vector<SpawnParams>& spawns,
                                                         const SolverParams& p) {
  std::vector<std::shared_ptr<const BodyMesh>> out;
  for (const RunObjects::Body& b : o.bodies) {
    std::shared_ptr<const BodyMesh> m;
    if (b.spawn >= 0 && b.spawn < static_cast<int>(spawns.size())) {
      const SpawnParams& s = spawns[b.spawn];
      if (s.shape == "sphere") m = sphere_mesh(0.5f * s.size.x);
      if (s.shape == "mesh") {
        m = obj_body_mesh(s, p);
        if (!m) spdlog::warn("rigid body mesh '{}' cannot be read here: drawing that body as a box", s.mesh);
      }
    }
    out.push_back(std::move(m));
  }
  return out;
}

std::vector<RigidDraw> rigid_draws(const std::vector<RigidFrame>& frames, const RunObjects& o,
                                   const std::vector<std::shared_ptr<const BodyMesh>>& meshes, float radius) {
  std::vector<RigidDraw> out;
  for (const RigidFrame& f : frames)
    for (std::size_t b = 0; b < o.bodies.size(); ++b) {
      if (o.bodies[b].first != f.first) continue;
      RigidDraw r;
      r.world_T_body = {kernels::quat_to_mat(f.rotation), f.centre};
      vec3 hi{0.f, 0.f, 0.f};  // the box around the rest offsets, plus the particles' radius
      for (vec3 q : o.bodies[b].rest) hi = vmax(hi, vec3{std::fabs(q.x), std::fabs(q.y), std::fabs(q.z)});
      r.half_extents = hi + vec3{radius, radius, radius};
      if (b < meshes.size()) r.mesh = meshes[b];
      out.push_back(std::move(r));
    }
  return out;
}

DrawList run_draw_list(const ParticleState& s, const std::vector<RigidFrame>& frames, const RunObjects& o,
                       const std::vector<std::shared_ptr<const BodyMesh>>& meshes, float radius) {
  DrawList d;
  d.positions = s.x, d.phases = s.phase, d.particle_radius = radius;
  d.rigids = rigid_draws(frames, o, meshes, radius);
  ClothDraw cloth;
  const auto n = static_cast<int>(s.x.size());
  for (const int3& t : o.cloth_triangles)
    if (t.x < n && t.y < n && t.z < n) cloth.triangles.push_back(t);  // sheets spawned by now
  if (!cloth.triangles.empty()) d.cloths.push_back(std::move(cloth));
  return d;
}

namespace {

// The solver's objects as drawn: re-collected only when something was spawned (rest shapes,
// spawn entries, body meshes).
class RunDrawState {
 public:
  void update(const ParticleSolver& solver, const std::vector<SpawnParams>& spawns) {
    frames_ = solver.rigid_frames();
    if (frames_.size() == objects_.bodies.size() && solver.cloth_triangles().size() == objects_.cloth_triangles.size())
      return;
    objects_ = collect_run_objects(solver, spawns);
    meshes_ = body_meshes(objects_, spawns, solver.params());
  }
  // Host path: the state is downloaded and kept here (the DrawList's spans point into it).
  DrawList host_list(const ParticleSolver& solver) {
    state_ = solver.download_state();
    return run_draw_list(state_, frames_, objects_, meshes_, radius(solver));
  }
  // Device path: everything but the particles, which the interop buffer holds.
  DrawList device_list(const ParticleSolver& solver) const {
    DrawList list;
    list.particle_radius = radius(solver);
    list.rigids = rigid_draws(frames_, objects_, meshes_, list.particle_radius);
    if (!objects_.cloth_triangles.empty()) list.cloths.push_back({objects_.cloth_triangles});
    return list;
  }

 private:
  static float radius(const ParticleSolver& s) { return 0.5f * s.params().particle_diameter; }
  std::vector<RigidFrame> frames_;
  RunObjects objects_;
  std::vector<std::shared_ptr<const BodyMesh>> meshes_;
  ParticleState state_;
};

class GlRunRenderer : public RunRenderer {
 public:
  explicit GlRunRenderer(RunContext& ctx)
      : ctx_(ctx),
        p_(ctx.experiment().render),
        renderer_(p_, p_.width, p_.height),
        out_(ctx.out_dir(), p_) {
    spdlog::info("rendering {}x{} {} view with {} ({})", p_.width, p_.height, p_.view, renderer_.gl_info().renderer,
                 renderer_.gl_info().version);
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
    if (p_.view != "mesh") return;
    renderer_.set_scene_mesh(mesh);
    if (have_recorded_camera_) return;  // the recorded frames set it
    mesh_camera_ = mesh_view_camera(mesh, scan_camera, p_);
    have_mesh_camera_ = true;
    set_mesh_camera(0.f);
  }

  void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) override {
    if (p_.view == "kinect") {
      renderer_.set_kinect_view(frame.rgb, frame.depth, frame.intrinsics, world_T_camera);
      camera_ = renderer_.kinect_camera();
    } else if (p_.camera == "recorded") {  // the mesh seen through the recorded camera
      camera_.K = scale_intrinsics(zoom_intrinsics(frame.intrinsics, p_.zoom, p_.zoom_at), p_.width, p_.height);
      camera_.world_T_camera = world_T_camera;
      camera_.znear = p_.znear, camera_.zfar = p_.zfar;
      have_recorded_camera_ = true;
    }
  }

  void draw(const ParticleSolver& solver) override {
    StageScope s(ctx_.timer(), "render");
    draw_state_.update(solver, ctx_.experiment().spawn);
    // The orbit's progress: simulated time over the run's duration (0 at the first frame).
    const double duration = ctx_.experiment().duration;
    if (p_.orbit_deg != 0.f && have_mesh_camera_ && !have_recorded_camera_ && duration > 0.0)
      set_mesh_camera(static_cast<float>(solver.stats().time / duration));
#if SEAMLESS_HAS_CUDA
    if (interop_ && solver.device() == Device::CUDA) {
      interop_->copy_from_device(solver.device_positions(), solver.device_phases(), solver.size());
      renderer_.draw_device_particles(draw_state_.device_list(solver), solver.size(), camera_);
      out_.add(renderer_);
      return;
    }
#endif
    renderer_.draw(draw_state_.host_list(solver), camera_);
    out_.add(renderer_);
  }

  void finish() override {
    out_.finish();
    // The last frame on its own: what a reader sees first of a run (scripts/demo prints it).
    if (out_.frames() > 0) write_png_rgb(ctx_.out_path("preview.png"), renderer_.read_frame());
    spdlog::info("rendered {} frames{}{}", out_.frames(), out_.video_open() ? " and " + out_.video_path() : "",
                 out_.frames() > 0 ? ", the last as preview.png" : "");
  }

 private:
  void set_mesh_camera(float progress) {
    const SceneCamera c = orbit_camera(mesh_camera_, p_, progress);
    camera_ = RenderCamera::look_at(c.eye, c.target, {0.f, 1.f, 0.f}, p_.fov_y, p_.width, p_.height, p_.znear, p_.zfar);
  }

  RunContext& ctx_;
  RenderParams p_;
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
  explicit WindowRunRenderer(RunContext& ctx) : ctx_(ctx) {}

  void set_scene(const Mesh& mesh, const SE3& scan_camera) override {
    mesh_ = mesh, mesh_camera_ = scan_camera, new_mesh_ = true;
  }
  void set_kinect_frame(const RgbdFrame& frame, const SE3& world_T_camera) override {
    rgb_ = frame.rgb.clone(Device::CPU), depth_ = frame.depth.clone(Device::CPU);
    K_ = frame.intrinsics, pose_ = world_T_camera, new_frame_ = true;
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
      draw_state_.update(loop.solver(), e.spawn);
      return draw_state_.host_list(loop.solver());
    };
    if (const int n = ctx_.window_frames(); n > 0)  // Esc before frame n-1: n frames are shown
      cb.scripted_keys = [n](int frame) { return frame == n - 1 ? std::vector<int>{GLFW_KEY_ESCAPE} : std::vector<int>{}; };
    spdlog::info("window: Space pause, N single step, G spawn the next object, 1-5 layers, F fluid style, "
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
    if (new_frame_) r.set_kinect_view(rgb_, depth_, K_, pose_);
    new_mesh_ = new_frame_ = false;
  }

  RunContext& ctx_;
  RunDrawState draw_state_;
  Mesh mesh_;
  SE3 mesh_camera_ = SE3::identity(), pose_ = SE3::identity();
  Image<uchar3> rgb_;
  Image<float> depth_;
  Intrinsics K_{};
  bool new_mesh_ = false, new_frame_ = false;
};

// Why no window can be opened here, or "" when one can.
std::string no_window_reason() {
  if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY"))
    return "no display (DISPLAY and WAYLAND_DISPLAY are unset; over ssh use ssh -X, or run under xvfb-run)";
  if (!window_available()) return "GLFW cannot connect to the display '" + std::string(std::getenv("DISPLAY") ? std::getenv("DISPLAY") : "") + "'";
  return "";
}
#endif

}  // namespace
#endif

std::unique_ptr<RunRenderer> RunRenderer::make(RunContext& ctx) {
  const RenderParams& p = ctx.experiment().render;
  if (p.mode == "none") return nullptr;
#if SEAMLESS_HAS_GL
  if (p.mode == "window") {
#if SEAMLESS_HAS_GLFW
    const std::string why = no_window_reason();
    if (why.empty()) return std::make_unique<WindowRunRenderer>(ctx);
#else
    const std::string why = "this build has no GLFW (apt-get install libglfw3-dev, then reconfigure)";
#endif
    spdlog::warn("render.mode is window but no window can be opened: {}; rendering headless into {}/frames instead",
                 why, ctx.out_dir());
  }
  return std::make_unique<GlRunRenderer>(ctx);
#else
  spdlog::warn("render.mode is {} but this build has no renderer (GL module off: apt-get install libegl-dev "
               "libgl-dev libepoxy-dev); continuing without pictures",
               p.mode);
  return nullptr;
#endif
}

}  // namespace seamless::app
