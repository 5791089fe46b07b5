#include "app/bench_pipeline.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include "app/exit_codes.hpp"
#include "app/json_file.hpp"
#include "app/pipeline.hpp"
#include "app/render_stage.hpp"
#include "app/run_context.hpp"
#include "config/config.hpp"
#include "core/buffer.hpp"
#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "seamless/build_config.hpp"
#include "seamless/git_commit.hpp"

namespace seamless::app {

namespace fs = std::filesystem;

namespace {

// The stages a frame is split into, in pipeline order. The tracking stages partition the session's
// frame time (TrackingSession::process marks): upload + preprocess + dynamic + track + allocate +
// fuse + raycast = frame (dynamic: the dynamic pixels, with dynamic.enabled only). Live mode adds
// the run's own stages of the frame (colliders: solver.dynamic_colliders only).
const std::vector<std::string> kTrackingStages = {"upload",   "preprocess", "dynamic", "track",
                                                  "allocate", "fuse",       "raycast"};
const std::vector<std::string> kLiveStages = {"colliders", "physics", "extract", "render"};
// The Kinect view's GPU time from its GL timer queries: printed and kept, but not part of the frame
// sum, since the render stage already holds the host's wait for it (see docs/PERFORMANCE.md).
const std::string kRenderGpu = "render_gpu";

// Linear interpolation between order statistics (numpy's default): q = 0.5 is the usual median,
// and the result never decreases with q, so median <= p90 <= max holds.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  const double pos = q * static_cast<double>(v.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  return v[lo] + (pos - static_cast<double>(lo)) * (v[hi] - v[lo]);
}

struct Summary {
  double median = 0, p90 = 0, max = 0;
};
Summary summarise(const std::vector<double>& v) { return {quantile(v, 0.5), quantile(v, 0.9), quantile(v, 1.0)}; }

struct RepResult {
  std::map<std::string, std::vector<double>> per_frame;  // stage -> one value a frame, in frame order
  std::int64_t frames = 0, lost = 0;
  std::size_t peak_buffer_bytes = 0;      // the memory ledger's peak on the run's device (Buffer allocations)
  std::int64_t peak_rss_bytes = -1;       // the process's high-water mark (VmHWM); -1 where unreadable
  double wall_s = 0;                      // the whole replay, PNG decoding and output files included
  double load_start = -1, load_end = -1;  // the machine's 1-minute load average around the replay; -1 unreadable
  int exit_code = kExitOk;
};

// Linux keeps the process's resident high-water mark (VmHWM); writing 5 to clear_refs resets it
// (proc(5)), so that each replay reports its own peak.
bool reset_peak_rss() {
  std::ofstream f("/proc/self/clear_refs");
  return static_cast<bool>(f << "5" << std::flush);
}
// The 1-minute load average (the first field of /proc/loadavg, proc(5)), -1 where unreadable: on a
// shared machine a replay's times mean little without it.
double load_average() {
  std::ifstream f("/proc/loadavg");
  double v = -1;
  return f >> v ? v : -1;
}
std::int64_t peak_rss_bytes() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::atoll(line.c_str() + 6) * 1024;  // "VmHWM:  1234 kB"
  return -1;
}

// The overrides the benchmark imposes, before the user's --set (which may change any of them).
std::vector<std::string> bench_overrides(const PipelineBenchOptions& o) {
  std::vector<std::string> s = {"device=" + std::string(device_name(o.device)), "output.write_mesh=false",
                                "output.particles_every=0"};
  if (!o.data.empty()) s.insert(s.end(), {"input.source=tum", "input.path=" + o.data});
  if (!o.tracker.empty()) s.push_back("tracker.kind=" + o.tracker);
  if (o.frames > 0) s.push_back("frames=" + std::to_string(o.frames));
  if (o.mode == "live")
    // The Kinect view of the live AR loop at 640x480, drawn but not written out (no PNGs, no video).
    s.insert(s.end(),
             {"mode=live", "render.mode=headless", "render.view=kinect", "render.fluid=ssfr", "render.width=640",
              "render.height=480", "render.write_frames=false", "render.video=false", "render.stage_images=false"});
  else s.push_back("mode=scan_then_simulate");
  s.insert(s.end(), o.sets.begin(), o.sets.end());
  return s;
}

// Live mode's physics: Table 5.1's fluid scene (the `physics` benchmark's fluid_10k), a block of
// 25 x 16 x 25 = 10,000 particles spawned at the start, 1.5 m in front of the first camera.
SpawnParams fluid_10k(const SolverParams& p) {
  SpawnParams s;
  s.kind = SpawnKind::fluid_block;
  s.time = 0.f;
  const float d = p.particle_diameter;
  s.size = {25 * d, 16 * d, 25 * d};
  s.position = {0.f, 0.f, 1.5f};
  return s;
}

Experiment load(const PipelineBenchOptions& o) {
  const std::vector<std::string> sets = bench_overrides(o);
  Experiment e = o.config.empty() ? parse_experiment("name: bench_pipeline\n", sets, "<bench pipeline defaults>")
                                  : load_experiment(o.config, sets);
  if (o.config.empty() && o.data.empty())
    throw UsageError("bench pipeline needs --data TUM_FOLDER (or --config with an input section)");
  if (o.mode == "live") e.spawn = {fluid_10k(e.solver)};
  return e;
}

// frame k's value of each stage the run's timer recorded (physics, extract, render), summed. The
// colliders are a stage only in runs that have them (solver.dynamic_colliders).
std::map<std::string, std::vector<double>> timer_stages(const StageTimer& t, std::int64_t frames, bool colliders) {
  std::map<std::string, std::vector<double>> out;
  for (const std::string& s : kLiveStages)
    if (s != "colliders" || colliders) out[s].assign(static_cast<std::size_t>(frames), 0.0);
  out[kRenderGpu].assign(static_cast<std::size_t>(frames), 0.0);
  for (const StageTimer::Row& r : t.rows()) {
    auto it = out.find(r.stage);
    if (it != out.end() && r.frame >= 0 && r.frame < frames) it->second[static_cast<std::size_t>(r.frame)] += r.ms;
  }
  return out;
}

// The tracking stages of each frame from its record (see kTrackingStages).
void add_tracking_stages(const std::vector<FrameRecord>& records, bool split_allocate, bool dynamic, RepResult& r) {
  for (const FrameRecord& f : records) {
    const double allocate = split_allocate && f.fused ? f.allocate_ms : 0.0;
    r.per_frame["upload"].push_back(f.upload_ms);
    r.per_frame["preprocess"].push_back(f.preprocess_ms - f.upload_ms);
    if (dynamic) r.per_frame["dynamic"].push_back(f.dynamic_ms);
    r.per_frame["track"].push_back(f.track_ms - f.dynamic_ms);  // 0 for the first frame, which defines the world
    if (split_allocate) r.per_frame["allocate"].push_back(allocate);
    r.per_frame["fuse"].push_back(f.fuse_ms - f.raycast_ms - allocate);  // 0 for a lost frame
    r.per_frame["raycast"].push_back(f.raycast_ms);
    r.per_frame["frame"].push_back(f.frame_ms);
    r.lost += f.result.ok() ? 0 : 1;
  }
  r.frames = static_cast<std::int64_t>(records.size());
}

// One whole replay into run folder `dir`, through the function of the command it stands for.
RepResult replay(const PipelineBenchOptions& o, const Experiment& e, const std::string& dir, std::string& render_note) {
  CommonOptions co;
  co.config = o.config.empty() ? "bench_pipeline" : o.config;
  co.out = dir;
  co.force = true;
  RepResult r;
  memory::reset_peak(o.device);
  const bool rss_reset = reset_peak_rss();
  r.load_start = load_average();
  const auto t0 = std::chrono::steady_clock::now();
  {
    Experiment run_e = e;
    if (o.mode == "scan") run_e.refine.enabled = false;  // scan() would refine: the pass is left out
    RunContext ctx(co, run_e);
    StageTimer volume_stages(ctx.device());
    StageTimer* vs = o.volume_stages ? &volume_stages : nullptr;
    if (o.mode == "scan") {
      const ScanResult s = scan(ctx, false, vs);  // what `seamless track` runs, less its refinement
      add_tracking_stages(s.tracking.frames, o.volume_stages, e.dynamic.enabled, r);
    } else {
      std::unique_ptr<RunRenderer> renderer;
      try {
        renderer = RunRenderer::make(ctx);  // null, with a warning, in a build without the GL module
        if (!renderer) render_note = "skipped: this build has no renderer (GL module off)";
      } catch (const std::exception& err) {
        render_note = std::string("skipped: no OpenGL context (") + err.what() + ")";
        spdlog::warn("bench pipeline: render stage {}", render_note);
      }
      const std::vector<FrameRecord> records = live(ctx, renderer.get(), vs);
      add_tracking_stages(records, o.volume_stages, e.dynamic.enabled, r);
      for (auto& [stage, v] :
           timer_stages(ctx.timer(), r.frames, e.solver.dynamic_colliders != DynamicColliders::none)) {
        if ((stage == "render" || stage == kRenderGpu) && !renderer) continue;
        if (stage != kRenderGpu)
          for (std::size_t k = 0; k < v.size(); ++k) r.per_frame["frame"][k] += v[k];
        r.per_frame[stage] = std::move(v);
      }
    }
    r.exit_code = ctx.exit_code();
  }
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  r.load_end = load_average();
  r.peak_buffer_bytes = memory::peak_bytes(o.device);
  if (rss_reset) r.peak_rss_bytes = peak_rss_bytes();
  return r;
}

std::vector<std::string> stage_order(const PipelineBenchOptions& o, const RepResult& r) {
  std::vector<std::string> order;
  auto add = [&](const std::vector<std::string>& names) {
    for (const std::string& s : names)
      if (r.per_frame.count(s)) order.push_back(s);
  };
  add(kTrackingStages);
  if (o.mode == "live") add(kLiveStages);
  order.push_back("frame");
  if (o.mode == "live") add({kRenderGpu});  // after the frame: not part of its sum
  return order;
}

void print_table(const std::vector<std::string>& stages, const std::vector<RepResult>& reps) {
  std::printf("\n%-12s %11s %11s %11s   %s\n", "stage", "median ms", "p90 ms", "max ms",
              reps.size() > 1 ? "median of each replay (the first three columns: medians over the replays)" : "");
  for (const std::string& s : stages) {
    std::vector<double> med, p90, mx;
    for (const RepResult& r : reps) {
      const Summary x = summarise(r.per_frame.at(s));
      med.push_back(x.median), p90.push_back(x.p90), mx.push_back(x.max);
    }
    std::string each;
    if (reps.size() > 1)
      for (double m : med) each += (each.empty() ? "" : " ") + std::to_string(m).substr(0, 8);
    std::printf("%-12s %11.3f %11.3f %11.3f   %s\n", s.c_str(), quantile(med, 0.5), quantile(p90, 0.5),
                quantile(mx, 0.5), each.c_str());
  }
}

void write_json(const std::string& path, const PipelineBenchOptions& o, const Experiment& e,
                const std::vector<std::string>& stages, const std::vector<RepResult>& reps,
                const std::string& render_note) {
  Json j = {{"benchmark", "pipeline"},
            {"seamless_version", SEAMLESS_VERSION},
            {"commit", SEAMLESS_GIT_COMMIT},
            {"device", device_name(o.device)},
            {"gpu", cuda_device_description()},
            {"mode", o.mode},
            {"config", o.config},
            {"data", e.input.path},
            {"tracker", e.tracker.kind},
            {"tracker_mode", enum_name(e.tracker.mode)},
            {"voxel_size", e.volume.voxel_size},
            {"volume", enum_name(e.volume.layout)},
            {"frames_requested", e.frames},
            {"reps", static_cast<int>(reps.size())}};
  j["render"] = render_note.empty() ? std::string(o.mode == "live" ? "measured" : "not in scan mode") : render_note;
  j["stages"] = stages;
  Json& medians = j["median_of_medians_ms"] = Json::object();
  for (const std::string& s : stages) {
    std::vector<double> med;
    for (const RepResult& r : reps) med.push_back(summarise(r.per_frame.at(s)).median);
    medians[s] = quantile(med, 0.5);
  }
  Json replays = Json::array();
  for (const RepResult& r : reps) {
    Json per_stage = Json::object();
    for (const std::string& s : stages) {
      const Summary x = summarise(r.per_frame.at(s));
      per_stage[s] = {
          {"median_ms", x.median}, {"p90_ms", x.p90}, {"max_ms", x.max}, {"per_frame_ms", r.per_frame.at(s)}};
    }
    replays.push_back({{"frames", r.frames},
                       {"lost_frames", r.lost},
                       {"wall_s", r.wall_s},
                       {"load_average", {r.load_start, r.load_end}},
                       {"peak_buffer_bytes", r.peak_buffer_bytes},
                       {"peak_rss_bytes", r.peak_rss_bytes},
                       {"exit_code", r.exit_code},
                       {"stages", std::move(per_stage)}});
  }
  j["replays"] = std::move(replays);
  write_json_file(path, j);
}

// A folder of its own under the system's temporary folder (mkdtemp: no two runs share one).
std::string temporary_folder() {
  std::string templ = (fs::temp_directory_path() / "seamless-bench-pipeline-XXXXXX").string();
  if (!mkdtemp(templ.data()))
    throw Error("bench pipeline: cannot create a temporary folder in " + fs::temp_directory_path().string() +
                "; give --out");
  return templ;
}

}  // namespace

int run_pipeline_bench(const PipelineBenchOptions& o) {
  if (o.mode != "scan" && o.mode != "live") throw UsageError("bench pipeline: --mode is scan or live, not " + o.mode);
  const Experiment e = load(o);
  const bool keep = !o.out.empty();
  const std::string root = keep ? o.out : temporary_folder();
  spdlog::info("bench pipeline: {} mode, {} of {} on {}{}, {} replay(s); run folders in {}{}", o.mode,
               e.frames > 0 ? std::to_string(e.frames) + " frames" : std::string("every frame"), e.input.path,
               device_name(o.device), o.device == Device::CUDA ? " (" + cuda_device_description() + ")" : "", o.reps,
               root, keep ? "" : " (removed at the end)");
  std::vector<RepResult> reps;
  std::string render_note;
  for (int k = 0; k < o.reps && !interrupted(); ++k)
    reps.push_back(replay(o, e, root + "/rep_" + std::to_string(k), render_note));
  if (!keep) {
    std::error_code ec;
    fs::remove_all(root, ec);
  }
  if (reps.empty() || reps.front().frames == 0)
    throw InputError("bench pipeline: no frame was replayed from " + e.input.path);
  const std::vector<std::string> stages = stage_order(o, reps.front());
  print_table(stages, reps);
  const RepResult& last = reps.back();
  std::printf(
      "\n%lld frames a replay (%lld lost in the last); peak %.1f MiB of %s buffers, peak RSS %s; "
      "PNG decoding is in no stage (the source decodes before the frame's first mark)\n",
      static_cast<long long>(last.frames), static_cast<long long>(last.lost), last.peak_buffer_bytes / 1048576.0,
      device_name(o.device),
      last.peak_rss_bytes < 0 ? "unknown" : (std::to_string(last.peak_rss_bytes >> 20) + " MiB").c_str());
  std::printf("load average %.2f at the start of the last replay, %.2f at its end\n", last.load_start, last.load_end);
  // A folder shorter than --frames gives figures over fewer (and other) frames than asked for:
  // said where the figures are read, not only in the log.
  if (e.frames > 0 && last.frames < e.frames) {
    std::printf("WARNING: --frames %lld asked for more frames than the source gave: the figures are over %lld\n",
                static_cast<long long>(e.frames), static_cast<long long>(last.frames));
    spdlog::warn("bench pipeline: {} frames asked for, {} replayed from {}", e.frames, last.frames, e.input.path);
  }
  if (o.mode == "live") std::printf("render: %s\n", render_note.empty() ? "measured" : render_note.c_str());
  if (!o.json.empty()) {
    write_json(o.json, o, e, stages, reps, render_note);
    spdlog::info("wrote {}", o.json);
  }
  int code = kExitOk;
  for (const RepResult& r : reps) code = std::max(code, r.exit_code);
  return code;
}

}  // namespace seamless::app
