#include "app/run_summary.hpp"

#include <cmath>
#include <set>

#include "core/error.hpp"
#include "core/json.hpp"
#include "core/output_file.hpp"
#include "eval/trajectory_eval.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

namespace seamless::app {

SceneBounds scene_bounds(const Mesh& mesh, vec3 up, const HorizontalSurface* floor) {
  SceneBounds b;
  b.up = up;
  if (floor) b.floor = floor->height;
  if (!mesh.positions.empty()) {
    b.lo = b.hi = mesh.positions[0];
    for (vec3 p : mesh.positions) b.lo = vmin(b.lo, p), b.hi = vmax(b.hi, p);
  }
  return b;
}

EscapedParticles count_escaped(const ParticleState& s, const SceneBounds& b, float diameter) {
  EscapedParticles e;
  const float margin = 2.f * diameter;
  const vec3 up = normalize(b.up);
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    if (s.inv_mass[i] == 0.f) continue;  // pinned cloth corners stay where they were put
    const vec3 x = s.x[i];
    const float h = dot(x, up);
    if (b.floor && h < *b.floor - margin) ++e.below_floor;
    else if (x.x < b.lo.x - margin || x.y < b.lo.y - margin || x.z < b.lo.z - margin || x.x > b.hi.x + margin ||
             x.y > b.hi.y + margin || x.z > b.hi.z + margin)
      ++e.outside;
    else if (-dot(s.v[i], up) > kFallSpeed)
      ++e.falling;
  }
  return e;
}

void add_tracking(RunSummary& s, const TrackSequenceResult& r, std::int64_t unreadable,
                  const std::string& groundtruth) {
  s.frames_read = static_cast<std::int64_t>(r.frames.size());
  s.frames_lost = r.lost_frames;
  s.frames_unreadable = unreadable;
  for (const FrameRecord& f : r.frames) s.frames_fused += f.fused;
  if (groundtruth.empty() || r.trajectory.empty()) return;
  const AteResult ate = compute_ate(r.trajectory, read_tum_trajectory(groundtruth));
  if (ate.trans.count == 0) return;
  s.ate_rmse_m = ate.trans.rmse;
  s.ate_pairs = static_cast<std::int64_t>(ate.trans.count);
}

void add_stage_medians(RunSummary& s, const StageTimer& t) {
  std::set<std::string> stages;
  for (const StageTimer::Row& r : t.rows()) stages.insert(r.stage);
  for (const std::string& st : stages) s.stage_median_ms.push_back({st, t.median_ms(st)});
}

namespace {
void vec_value(JsonWriter& j, vec3 v) { j.begin_array().value(v.x).value(v.y).value(v.z).end_array(); }
}  // namespace

void write_summary(const std::string& path, const RunSummary& s) {
  JsonWriter j;
  j.begin_object();
  j.field("seamless_version", SEAMLESS_VERSION).field("commit", SEAMLESS_GIT_COMMIT);
  j.field("command", s.command).field("config", s.config).field("device", s.device);
  if (s.intrinsics) {
    const Intrinsics& K = *s.intrinsics;
    j.key("intrinsics").begin_object().field("fx", K.fx).field("fy", K.fy).field("cx", K.cx).field("cy", K.cy);
    j.field("width", K.width).field("height", K.height).end_object();
  }
  j.key("frames").begin_object().field("read", s.frames_read).field("lost", s.frames_lost);
  j.field("fused", s.frames_fused).field("unreadable", s.frames_unreadable).end_object();
  if (s.ate_rmse_m) j.key("ate").begin_object().field("rmse_m", *s.ate_rmse_m).field("pairs", s.ate_pairs).end_object();
  if (s.floor_height) j.field("floor_height", *s.floor_height);
  j.key("surfaces").begin_array();
  for (std::size_t i = 0; i < s.surfaces.size() && i < 10; ++i) {
    const HorizontalSurface& h = s.surfaces[i];
    j.begin_object().field("area_m2", h.area).field("height", h.height).key("centre");
    vec_value(j, h.centre);
    j.field("open_radius", h.open_radius).field("floor", h.floor).end_object();
  }
  j.end_array();
  j.key("spawns").begin_array();
  for (std::size_t i = 0; i < s.spawns.size(); ++i) {
    const SpawnParams& sp = s.spawns[i];
    j.begin_object().field("index", i).field("kind", sp.kind).field("time", sp.time).key("position");
    vec_value(j, sp.position);
    for (const ResolvedPlacement& r : s.placements)
      if (r.spawn == static_cast<int>(i)) {
        j.field("placed", r.how).key("surface_point");
        vec_value(j, r.surface_point);
      }
    j.end_object();
  }
  j.end_array();
  if (s.physics) {
    const SolverStats& p = *s.physics;
    j.key("particles").begin_object().field("dynamic", p.particles).field("fluid", p.fluid_particles);
    j.field("cloth", p.cloth_particles).field("rigid", p.rigid_particles).field("rigid_bodies", p.rigid_bodies);
    j.field("static", p.static_particles).field("simulated_s", p.time).field("steps", p.steps);
    j.field("neighbour_overflow", p.neighbour_overflow).field("emitter_dropped", p.emitter_dropped);
    if (s.escaped) {
      j.field("escaped", s.escaped->total()).field("escaped_below_floor", s.escaped->below_floor);
      j.field("escaped_outside", s.escaped->outside).field("escaped_falling", s.escaped->falling);
    }
    j.end_object();
  }
  j.key("stage_median_ms").begin_object();
  for (const auto& [stage, ms] : s.stage_median_ms) j.field(stage, ms);
  j.end_object().end_object();
  // Written complete under a temporary name, then renamed: a reader never sees half a file.
  j.write_file(partial_path(path));
  commit_partial(path);
}

}  // namespace seamless::app
