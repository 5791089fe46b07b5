#include "app/run_summary.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <set>

#include "app/json_file.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "core/output_file.hpp"
#include "eval/trajectory_eval.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

namespace seamless::app {

std::optional<float> floor_height(const HorizontalSurface* floor) {
  return floor ? std::optional<float>(floor->height) : std::nullopt;
}

SceneBounds scene_bounds(const Mesh& mesh, vec3 up, const HorizontalSurface* floor) {
  return mesh_bounds(mesh, up, floor_height(floor));
}

std::optional<double> mean_dynamic_fraction(const std::vector<FrameRecord>& frames) {
  double masked = 0;
  std::int64_t with_mask = 0;
  for (const FrameRecord& f : frames)
    if (std::isfinite(f.dynamic_fraction)) masked += f.dynamic_fraction, ++with_mask;
  if (with_mask == 0) return std::nullopt;
  return masked / static_cast<double>(with_mask);
}

void add_tracking(RunSummary& s, const TrackSequenceResult& r, std::int64_t unreadable,
                  const std::string& groundtruth) {
  s.frames_read = static_cast<std::int64_t>(r.frames.size());
  s.frames_lost = r.lost_frames;
  s.frames_unreadable = unreadable;
  for (const FrameRecord& f : r.frames) s.frames_fused += f.fused;
  s.dynamic_masked_fraction = mean_dynamic_fraction(r.frames);
  if (groundtruth.empty() || r.trajectory.empty()) return;
  AteResult ate;
  try {
    ate = compute_ate(r.trajectory, read_tum_trajectory(groundtruth));
  } catch (const Error& e) {  // too few poses for an alignment (a 2-frame run): no ATE, not a failed run
    spdlog::info("summary.json: no ATE ({})", e.what());
    return;
  }
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
Json vec_json(vec3 v) { return Json::array({v.x, v.y, v.z}); }

Json median_max(const std::vector<double>& v) {
  if (v.empty()) return {{"median", 0.0}, {"max", 0.0}, {"count", 0}};
  return {{"median", median(v)}, {"max", *std::max_element(v.begin(), v.end())}, {"count", v.size()}};
}

// refine.online: the tracking thread's time per frame (handover_ms) and the background's per
// keyframe and per Ceres solve (docs/PLACEMENT.md, "summary.json").
Json online_json(const OnlineRefineStats& o) {
  return {{"keyframes", o.keyframes},
          {"solves", o.solves},
          {"corrections", o.corrections},
          {"pair_edges", o.pair_edges},
          {"rejected_pairs", o.rejected_pairs},
          {"candidate_pairs", o.candidate_pairs},
          {"max_correction_m", o.max_correction_m},
          {"max_correction_deg", o.max_correction_deg},
          {"handover_ms", median_max(o.handover_ms)},
          {"keyframe_s", median_max(o.keyframe_s)},
          {"solve_s", median_max(o.solve_s)},
          {"final_wait_s", o.final_wait_s}};
}
// A NaN (a mover never in view, nothing masked) as null: JSON has no NaN.
Json number_or_null(double v) { return std::isfinite(v) ? Json(v) : Json(nullptr); }

Json mask_json(const MaskQuality& q) {
  Json below = Json::array(), recall = Json::array();
  for (const auto& [frame, iou] : q.below) below.push_back({{"frame", frame}, {"iou", iou}});
  for (double r : q.mover_recall) recall.push_back(number_or_null(r));
  return {{"frames_scored", q.frames},
          {"iou_min", number_or_null(q.min_iou)},
          {"iou_mean", number_or_null(q.mean_iou)},
          {"frames_under_0_8", below},
          {"recall_by_mover", recall},
          {"precision", number_or_null(q.precision)}};
}
}  // namespace

void write_summary(const std::string& path, const RunSummary& s) {
  Json j;
  const int sig = interrupt_signal();
  j["status"] = !s.status.empty() ? s.status : sig != 0 ? "interrupted" : "complete";
  if (sig != 0) j["signal"] = signal_name(sig);
  j["reached"] = {{"frames", s.reached_frames >= 0 ? s.reached_frames : s.frames_read},
                  {"steps", s.reached_steps >= 0 ? s.reached_steps
                            : s.physics          ? s.physics->steps
                                                 : 0}};
  if (!s.error.empty()) j["error"] = s.error;
  if (s.exit_code >= 0) j["exit_code"] = s.exit_code;
  j["seamless_version"] = SEAMLESS_VERSION;
  j["commit"] = SEAMLESS_GIT_COMMIT;
  j["command"] = s.command, j["config"] = s.config, j["device"] = s.device;
  if (s.intrinsics) {
    const Intrinsics& K = *s.intrinsics;
    j["intrinsics"] = {{"fx", K.fx}, {"fy", K.fy},       {"cx", K.cx},
                       {"cy", K.cy}, {"width", K.width}, {"height", K.height}};
  }
  j["frames"] = {
      {"read", s.frames_read}, {"lost", s.frames_lost}, {"fused", s.frames_fused}, {"unreadable", s.frames_unreadable}};
  if (s.ate_rmse_m) j["ate"] = {{"rmse_m", *s.ate_rmse_m}, {"pairs", s.ate_pairs}};
  if (s.dynamic_masked_fraction || s.ghost_vertices || s.mask_quality || s.inside_people) {
    Json& d = j["dynamic"] = Json::object();
    if (s.dynamic_masked_fraction) d["mean_masked_fraction"] = *s.dynamic_masked_fraction;
    if (s.ghost_vertices) {
      d["ghost_vertices"] = s.ghost_vertices->total;
      d["ghost_vertices_by_mover"] = s.ghost_vertices->by_mover;
    }
    if (s.mask_quality) d["mask"] = mask_json(*s.mask_quality);
    if (s.inside_people) {
      const InsidePeopleStats& p = *s.inside_people;
      d["inside_people"] = {{"frames_checked", p.frames_checked},
                            {"max_inside", p.max_inside},
                            {"max_inside_frame", p.max_inside_frame},
                            {"frames_resting", p.frames_resting},
                            {"max_resting", p.max_resting},
                            {"rest_frames", p.rest_frames},
                            {"margin_m", p.margin},
                            {"thickness_m", p.thickness}};
    }
  }
  if (s.seen_through)
    j["ghost"] = {{"seen_through_vertices", s.seen_through->vertices},
                  {"mesh_vertices", s.seen_through->mesh_vertices},
                  {"fraction", s.seen_through->fraction()},
                  {"views", s.seen_through->views}};
  if (s.floor_height) j["floor_height"] = *s.floor_height;
  Json& surfaces = j["surfaces"] = Json::array();
  for (std::size_t i = 0; i < s.surfaces.size() && i < 10; ++i) {
    const HorizontalSurface& h = s.surfaces[i];
    surfaces.push_back({{"area_m2", h.area},
                        {"height", h.height},
                        {"centre", vec_json(h.centre)},
                        {"open_radius", h.open_radius},
                        {"floor", h.floor}});
  }
  Json& spawns = j["spawns"] = Json::array();
  for (std::size_t i = 0; i < s.spawns.size(); ++i) {
    const SpawnParams& sp = s.spawns[i];
    Json e = {{"index", i}, {"kind", enum_name(sp.kind)}, {"time", sp.time}, {"position", vec_json(sp.position)}};
    for (const ResolvedPlacement& r : s.placements)
      if (r.spawn == static_cast<int>(i)) e["placed"] = r.how, e["surface_point"] = vec_json(r.surface_point);
    spawns.push_back(std::move(e));
  }
  if (s.physics) {
    const SolverStats& p = *s.physics;
    Json ph = {{"dynamic", p.particles},
               {"fluid", p.fluid_particles},
               {"cloth", p.cloth_particles},
               {"rigid", p.rigid_particles},
               {"rigid_bodies", p.rigid_bodies},
               {"static", p.static_particles},
               {"simulated_s", p.time},
               {"steps", p.steps},
               {"neighbour_overflow", p.neighbour_overflow},
               {"emitter_dropped", p.emitter_dropped}};
    if (s.escaped) {
      ph["escaped"] = s.escaped->total(), ph["escaped_below_floor"] = s.escaped->below_floor;
      ph["escaped_outside"] = s.escaped->outside, ph["escaped_falling"] = s.escaped->falling;
    }
    j["particles"] = std::move(ph);
  }
  Json& stages = j["stage_median_ms"] = Json::object();
  for (const auto& [stage, ms] : s.stage_median_ms) stages[stage] = ms;
  if (s.online_refine) j["online_refine"] = online_json(*s.online_refine);
  // Written complete under a temporary name, then renamed: a reader never sees half a file.
  write_json_file(partial_path(path), j);
  commit_partial(path);
}

}  // namespace seamless::app
