// The solver's object model beyond the particles (ParticleSolver::objects() holds it, core's
// SceneObjects is its shape): the one rule for when a spawn entry is spawned, the surface a rigid
// body is drawn with, and each body's frame in a saved state (a finished run's particles_<step>.ply,
// where there is no solver to ask).
#pragma once
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <vector>

#include "core/particles.hpp"
#include "physics/solver_params.hpp"

namespace seamless {

// What spawns when: an entry is spawned at the start of the first step whose start time reaches
// its `time` (within 1e-9 s of float rounding), entries due at one step in list order. A gate may
// hold a due entry back (live mode: its placement needs a surface not scanned yet); it is asked
// again at the next step.
class SpawnSchedule {
 public:
  struct Entry {
    int index = -1;  // in the scheduled list (counted over every add())
    SpawnParams s;
  };
  // May change the entry (live mode resolves its position) and return true to let it spawn now.
  using Gate = std::function<bool(int index, SpawnParams& s)>;

  void add(const std::vector<SpawnParams>& spawns);
  // Calls spawn(entry) for each entry due at a step starting at `time` that the gate (if any) lets
  // through, in list order, and forgets them.
  void spawn_due(double time, const Gate& gate, const std::function<void(const Entry&)>& spawn);
  // The pending entry with the earliest time (the first of equals), taken out of the schedule.
  std::optional<Entry> take_next();
  std::size_t pending() const { return pending_.size(); }

 private:
  std::vector<Entry> pending_;
  int added_ = 0;
};

// A rigid body's surface in its body frame, from its spawn entry: a sphere of diameter size.x, the
// OBJ of `shape: mesh` placed as make_rigid voxelised it, or null (drawn as the box around its rest
// offsets) for boxes. Throws seamless::InputError when the OBJ cannot be read.
std::shared_ptr<const BodyMesh> body_mesh(const SpawnParams& s, const SolverParams& p);
// The meshes of bodies read from a finished run's objects.txt, from the run's spawn list; a body
// whose OBJ cannot be read any more is drawn as a box (with a warning).
void attach_body_meshes(SceneObjects& objects, const std::vector<SpawnParams>& spawns, const SolverParams& p);

// Each body's frame in a saved state (no solver to ask; during a run, ParticleSolver::rigid_frames
// gives the solver's own) by shape matching (Mueller et al. 2005, eq. 7): c = mean of x, R = the
// rotation of A = sum (x - c) q^T (kernels::extract_rotation, warm-started from `warm`, which is
// updated; pass the previous snapshot's result). Bodies not in the state are skipped.
std::vector<RigidFrame> rigid_frames_of_state(const SceneObjects& o, const ParticleState& s, std::vector<vec4>& warm);

}  // namespace seamless
