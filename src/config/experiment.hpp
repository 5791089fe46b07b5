// The whole experiment file: one struct per section, each owned by its layer and described by
// visit() (core/params.hpp). src/config loads it from YAML, validates it and writes it back.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/params.hpp"
#include "io/input_params.hpp"
#include "physics/solver_params.hpp"
#include "recon/dynamic_params.hpp"
#include "recon/preprocess_params.hpp"
#include "recon/refine/refine_params.hpp"
#include "recon/tracker_params.hpp"
#include "recon/volume_params.hpp"
#include "render/render_params.hpp"

namespace seamless {

enum class ExperimentMode { live, scan_then_simulate };
inline std::span<const EnumName<ExperimentMode>> enum_names(ExperimentMode) {
  static constexpr EnumName<ExperimentMode> names[] = {{ExperimentMode::live, "live"},
                                                       {ExperimentMode::scan_then_simulate, "scan_then_simulate"}};
  return names;
}

// What a run writes into its output folder.
struct OutputParams {
  std::string dir = "out";
  bool write_config = true;        // effective config (every key, after --set) as config.yaml
  bool write_mesh = true;          // mesh.ply (marching cubes, with colour)
  bool write_trajectory = true;    // trajectory.txt, TUM format
  bool write_timings = true;       // timings.csv, one row per frame and stage
  bool write_stats = true;         // tracking_stats.csv: per-frame residual, inliers, timings
  int particles_every = 25;        // write particles_<step>.ply every this many solver steps; 0 = only the last
  double max_lost_fraction = 0.2;  // a run whose tracking loses more of its frames exits with code 6
  // summary.json's seen-through ghost (app/ghost.hpp): with tracking alone (`seamless track`) it
  // extracts the tracker's whole model mesh; trajectory-only evaluations (scripts/compare_trackers)
  // turn it off.
  bool seen_through = true;

  template <class V> void visit(V& v) {
    v("dir", dir, "output folder (created if missing)");
    v("write_config", write_config, "write the effective config as config.yaml");
    v("write_mesh", write_mesh, "write the reconstructed mesh as mesh.ply");
    v("write_trajectory", write_trajectory, "write the camera trajectory (TUM format) as trajectory.txt");
    v("write_timings", write_timings, "write per-stage timings as timings.csv");
    v("write_stats", write_stats, "write per-frame tracking statistics as tracking_stats.csv");
    v("particles_every", particles_every, "write particles_<step>.ply every this many solver steps; 0 = only the last",
      Range{0, 1e9});
    v("max_lost_fraction", max_lost_fraction,
      "a run whose tracking loses more than this fraction of its frames exits with code 6 (README, exit codes); "
      "1 = never",
      Range{0, 1});
    v("seen_through", seen_through,
      "count the mesh vertices that at least two tracked frames saw through (summary.json ghost); with "
      "`seamless track` this extracts the tracker's model mesh");
  }
};

struct Experiment {
  std::string name = "experiment";
  std::string device = "auto";
  ExperimentMode mode = ExperimentMode::live;
  std::int64_t frames = 0;           // 0 = as many as the input gives
  double duration = 3.0;             // simulated seconds after the scan (scan_then_simulate)
  bool floor_plane = true;           // scan_then_simulate: an infinite floor under the scanned floor
  std::vector<float> support_plane;  // [height]: an infinite horizontal plane there (world y, metres); empty: none
  float scene_interior_depth = 0.f;  // scene particles also fill the solid this deep below the surface
  int reextract_every = 10;          // live mode: scene particles re-extracted every this many fused frames
  InputParams input;
  PreprocessParams preprocess;
  VolumeParams volume;
  TrackerParams tracker;
  DynamicParams dynamic;
  RefineParams refine;
  SolverParams solver;
  std::vector<SpawnParams> spawn;
  RenderParams render;
  OutputParams output;

  // Rules across keys and sections and physical sanity, checked once the whole file is read
  // (parse_experiment), so a bad combination is a config error before any work starts
  // (src/config/config.cpp). check() appends every problem; validate() throws them all.
  void check(std::vector<std::string>& problems) const;
  void validate() const;

  template <class V> void visit(V& v) {
    v("name", name, "experiment name (used in logs and output names)");
    v("device", device, "compute backend (auto: CUDA when built and a GPU is present)", Choices{"cpu", "cuda", "auto"});
    v("mode", mode, "reconstruct and simulate at once, or scan first then simulate");
    v("frames", frames, "frames to process; 0 = all the input has", Range{0, 1e12});
    v("floor_plane", floor_plane,
      "collide with an infinite plane at the scanned floor's height (unseen floor "
      "would otherwise let objects fall through)");
    v("support_plane", support_plane,
      "[height]: collide with an infinite horizontal plane at this height (world y, metres along -gravity from "
      "the first camera): a surface the depth camera does not measure (a glossy table seen at a grazing angle); "
      "empty: none",
      Range{-100.0, 100.0});
    v("scene_interior_depth", scene_interior_depth,
      "scene particles also fill the scanned solid this deep below its surface (metres; 0: surface only). A "
      "second layer stops particles that squeeze between surface particles where the scan is thin or has seams",
      Range{0.0, 2.0});
    v("reextract_every", reextract_every, "live mode: re-extract the scene particles every this many fused frames",
      Range{1, 1e6});
    v("duration", duration, "simulated seconds after the scan (scan_then_simulate mode, and simulate)", Range{0, 1e6});
    v("input", input, "where frames come from");
    v("preprocess", preprocess, "depth filtering, pyramid, vertex and normal maps");
    v("volume", volume, "TSDF volume");
    v("tracker", tracker, "camera tracking");
    v("dynamic", dynamic,
      "people and moving objects: kept out of tracking and fusion, free space carved (docs/DYNAMIC.md)");
    v("refine", refine, "offline keyframe pose-graph refinement of the tracked trajectory (Ceres)");
    v("solver", solver, "particle solver");
    v("spawn", spawn, "what to drop into the scene and when (list)");
    v("render", render, "rendering");
    v("output", output, "what to write into the output folder");
  }
};

}  // namespace seamless
