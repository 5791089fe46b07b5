// What a run says about itself: which dynamic particles escaped the scanned scene, and summary.json
// (docs/PLACEMENT.md, "summary.json"), which scripts read instead of log lines.
#pragma once
#include <optional>
#include <string>
#include <vector>

#include "app/escaped.hpp"
#include "app/ghost.hpp"
#include "app/placement.hpp"
#include "core/intrinsics.hpp"
#include "physics/depth_colliders.hpp"
#include "physics/particle_solver.hpp"
#include "recon/refine/online_refine.hpp"
#include "recon/tracker_sequence.hpp"

namespace seamless::app {

// The scanned mesh's bounds, `up`, and the floor's height when `floor` is not null (app/escaped.hpp).
SceneBounds scene_bounds(const Mesh& mesh, vec3 up, const HorizontalSurface* floor);
// The floor's height along up, where the scan found a floor.
std::optional<float> floor_height(const HorizontalSurface* floor);

struct RunSummary {
  // complete | interrupted | failed | incomplete (README, "Exit codes and interrupted runs");
  // empty: write_summary decides between complete and interrupted (core/interrupt.hpp).
  std::string status;
  std::string error;   // failed: the message
  int exit_code = -1;  // failed: the command's exit code (-1: not written)
  // How far the run got (failed and interrupted runs): -1 takes frames.read and the solver's steps.
  std::int64_t reached_frames = -1, reached_steps = -1;
  std::string command, config, device;
  std::optional<Intrinsics> intrinsics;
  std::int64_t frames_read = 0, frames_lost = 0, frames_fused = 0, frames_unreadable = 0;
  std::optional<double> ate_rmse_m;  // against the input's ground truth, when it has one
  std::int64_t ate_pairs = 0;
  std::optional<double> dynamic_masked_fraction;  // dynamic.enabled: mean over the tracked frames
  std::optional<GhostCount> ghost_vertices;       // synthetic movers: what they left in the map (app/ghost.hpp)
  std::optional<SeenThroughGhost> seen_through;   // any source: mesh vertices the frames saw through (app/ghost.hpp)
  std::optional<MaskQuality> mask_quality;        // synthetic movers: the dynamic mask against their masks
  // live mode with dynamic.enabled: the dynamic particles inside the people the frames saw
  std::optional<InsidePeopleStats> inside_people;
  std::vector<ResolvedPlacement> placements;
  std::vector<SpawnParams> spawns;  // as resolved
  std::optional<SolverStats> physics;
  std::optional<EscapedParticles> escaped;
  std::optional<float> floor_height;        // of the floor found in the scan (along up), when one was seen
  std::vector<HorizontalSurface> surfaces;  // the scan's horizontal surfaces, largest first
  std::vector<std::pair<std::string, double>> stage_median_ms;
  std::optional<OnlineRefineStats> online_refine;  // refine.online: its cost and what it did
};

// Frames, loss and ATE (when `groundtruth` is not empty) of a tracked sequence.
// dynamic.enabled: the mean fraction of pixels masked as dynamic over the frames that have a mask.
std::optional<double> mean_dynamic_fraction(const std::vector<FrameRecord>& frames);

void add_tracking(RunSummary& s, const TrackSequenceResult& r, std::int64_t unreadable, const std::string& groundtruth);
// The medians of every stage in the run's timer.
void add_stage_medians(RunSummary& s, const StageTimer& t);
// Writes summary.json (as NAME.partial, then renamed: a reader never sees half a file).
void write_summary(const std::string& path, const RunSummary& s);

}  // namespace seamless::app
