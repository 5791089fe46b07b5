// Kinematic collider particles from a depth camera's view (solver.dynamic_colliders, docs/DYNAMIC.md): a
// person or object the camera sees moving becomes, each frame, a set of infinitely heavy particles
// at its measured surface, so that the solver's ordinary scene contacts push fluid, cloth and rigid
// bodies out of it (Macklin et al. 2014's particle contacts, section 4.3; colliding particles with
// the live depth map is the idea of Google's DepthLab, Du et al. UIST 2020). The camera sees only
// the front of a body, so each point is extended along its camera ray by `thickness`: a particle
// pushed through the front layer meets the next one instead of ending inside the body.
#pragma once
#include <cstdint>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "kernels/physics/depth_colliders.hpp"

namespace seamless {

// The colliders between two frames, on a device, from the maps the tracker leaves there (live
// mode). A depth camera gives no correspondences, so each point's velocity is its displacement
// along the surface normal from the previous frame's nearest point within max_speed * dt (point to
// plane, as in ICP: exact for a surface moving along its normal whatever the pixels' positions on
// it; the motion along the surface, which pushes nothing, is not seen). The colliders then move
// with those velocities across the solver steps between the frames instead of jumping once a
// frame: a position-based contact turns a jump into the pushed particle's velocity over one step
// (a body walking at 1 m/s at 30 Hz would fling what it touches at 3.3 m/s with 0.01 s steps).
// The level's mask (block_any of the full-resolution dynamic mask), the seen surface, the
// velocities and the thickened colliders are kernels (kernels/physics/depth_colliders.hpp) and the
// colliders go to the solver as a device buffer (ParticleSolver::set_collider_particles), so no
// map passes through the host; the nearest-point search is one independent query per point,
// through a grid of the previous frame's points sorted by cell. tests/physics/host_colliders.hpp
// is the same computation written plainly on the host, the tests' oracle (on the CPU bit for bit).
class DeviceColliders {
 public:
  DeviceColliders(float spacing, float thickness, float max_speed, Device d);
  // A new frame, seen at simulation time t: vertex and normal maps (camera coordinates, row-major,
  // z <= 0 = no reading, the zero vector = no normal) on the device; full_mask: null for every pixel, else the
  // full-resolution dynamic mask (a pixel of the maps is used when any full-resolution pixel it
  // averages is nonzero; an empty image: none is).
  void update(const Image<vec3>& camera_vertices, const Image<vec3>& camera_normals, const SE3& world_T_camera,
              const Image<std::uint8_t>* full_mask, double t);
  // The colliders at time t, in [previous frame's time, this frame's], in points()[0, count), count
  // returned: each surface point moved back from this frame's position by its velocity times (this
  // frame's time - t), and behind it along its camera ray one more every `spacing` metres up to
  // `thickness`.
  std::int64_t at(double t);
  const Buffer<vec3>& points() const { return out_; }
  // This frame's surface points and their velocities (first size() of each; tests).
  std::int64_t size() const { return count_; }
  const Buffer<vec3>& surface_points() const { return points_; }
  const Buffer<vec3>& velocities() const { return velocity_; }

 private:
  void estimate_velocities(double dt);
  float spacing_, thickness_, max_speed_;
  Device dev_;
  Buffer<vec3> points_, rays_, normals_, last_points_, last_rays_, last_normals_, velocity_, out_;
  Buffer<std::uint8_t> level_mask_;
  Buffer<int> used_, offset_, idx_, start_;
  Buffer<std::uint32_t> keys_;
  std::int64_t count_ = 0, last_count_ = 0;
  double time_ = 0.0;
  bool have_ = false;
};

// The colliders' check (live mode, dynamic.inside_people of summary.json): after each frame's
// physics, the dynamic particles that lie inside a person the frame sees, i.e. inside the shell the
// depth colliders stand for: on a pixel of the dynamic mask, more than `margin` and less than
// `thickness` behind the measured surface along the particle's ray (kernels::DepthColliders::inside).
// A particle inside for more than rest_frames frames in a row rests inside: the colliders failed
// to push it out.
struct InsidePeopleStats {
  std::int64_t frames_checked = 0;
  std::int64_t max_inside = 0;         // the most particles inside in one frame
  std::int64_t frames_resting = 0;     // frames where some particle had been inside for more than rest_frames frames
  std::int64_t max_resting = 0;        // the most such particles in one frame
  std::int64_t max_inside_frame = -1;  // the frame (index in the run) where max_inside first was
  int rest_frames = 0;
  float margin = 0.f, thickness = 0.f;
};

class InsidePeopleCheck {
 public:
  InsidePeopleCheck(float margin, float thickness, int rest_frames, Device d);
  // One frame: n particles at world positions p (in id order, on d; the ids stay the particles'
  // from frame to frame, new ones appended), the frame's pose, the full-resolution intrinsics of
  // `mask` (the dynamic mask) and an unmasked pyramid level's vertex map (camera coordinates).
  kernels::InsideCount check(const vec3* p, std::int64_t n, const SE3& world_T_camera, const Intrinsics& K,
                             const Image<std::uint8_t>& mask, const Image<vec3>& level_vertices, std::int64_t frame);
  const InsidePeopleStats& stats() const { return stats_; }

 private:
  Device dev_;
  Buffer<int> run_;  // per particle: the frames in a row it has been inside
  InsidePeopleStats stats_;
};

}  // namespace seamless
