// seamless bench <name>: warm-up, N repetitions, min/median/max, JSON.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdio>

#include "app/bench.hpp"
#include "app/bench_pipeline.hpp"
#include "app/commands.hpp"
#include "app/json_file.hpp"
#include "core/error.hpp"
#include "core/timing.hpp"
#include "seamless/build_config.hpp"

namespace seamless::app {

namespace {
struct BenchArgs {
  std::string name, device = "auto", json, data, filter, scale = "all";
  int reps = 0, warmup = 5;  // reps 0: the benchmark's default (50; pipeline 1)
  bool list = false;
  // bench pipeline only
  std::string config, tracker, mode = "scan", out;
  std::vector<std::string> sets;
  std::int64_t frames = 0;
  bool no_volume_stages = false;
};

const char* kPipelineDescription =
    "a real sequence replayed once through `seamless track` (--mode scan) or live mode (--mode live: + 10k fluid "
    "particles, Kinect-view render 640x480): per-stage and per-frame median/p90/max, peak memory; --data TUM folder";

int run_pipeline(const BenchArgs& a) {
  PipelineBenchOptions p;
  p.data = a.data, p.config = a.config, p.sets = a.sets, p.tracker = a.tracker, p.mode = a.mode;
  p.frames = a.frames, p.reps = a.reps > 0 ? a.reps : 1, p.device = resolve_device(a.device);
  p.out = a.out, p.json = a.json, p.volume_stages = !a.no_volume_stages;
  return run_pipeline_bench(p);
}

struct CaseResult {
  std::string name, detail;
  int reps;
  double min_ms, median_ms, max_ms;
};

void write_json(const std::string& path, const std::string& bench, Device dev, const std::vector<CaseResult>& rows) {
  Json cases = Json::array();
  for (const CaseResult& c : rows)
    cases.push_back({{"name", c.name},
                     {"reps", c.reps},
                     {"min_ms", c.min_ms},
                     {"median_ms", c.median_ms},
                     {"max_ms", c.max_ms},
                     {"detail", c.detail}});
  write_json_file(path, {{"benchmark", bench},
                         {"seamless_version", SEAMLESS_VERSION},
                         {"device", device_name(dev)},
                         {"gpu", cuda_device_description()},
                         {"cases", std::move(cases)}});
}

int run_bench(BenchArgs a) {
  if (a.name == "pipeline") return run_pipeline(a);
  if (!a.config.empty() || !a.tracker.empty() || !a.out.empty() || !a.sets.empty() || a.frames > 0 ||
      a.no_volume_stages || a.mode != "scan")
    throw UsageError(
        "--config, --set, --tracker, --mode, --frames, --out and --no-volume-stages are options of "
        "`seamless bench pipeline` only");
  if (a.reps == 0) a.reps = 50;
  auto& reg = bench_registry();
  auto it = reg.find(a.name);
  if (it == reg.end()) {
    std::string names;
    for (auto& [n, info] : reg) names += "\n  " + n + ": " + info.description;
    names += std::string("\n  pipeline: ") + kPipelineDescription;
    throw UsageError("no benchmark named '" + a.name + "'; this build has:" + names);
  }
  BenchOptions o{resolve_device(a.device), a.data, a.filter, a.scale};
  if (it->second.custom) return it->second.custom(o, a.reps, a.json);
  spdlog::info("bench {} on {} {}", a.name, device_name(o.device), cuda_device_description());
  std::vector<CaseResult> json_rows;
  std::printf("%-32s %10s %10s %10s  %s\n", "case", "min ms", "median ms", "max ms", "detail");
  for (BenchCase& c : it->second.factory(o)) {
    if (!a.filter.empty() && c.name.find(a.filter) == std::string::npos) continue;
    for (int i = 0; i < a.warmup; ++i) measure_ms(o.device, c.step);
    std::vector<double> t;
    for (int i = 0; i < a.reps; ++i) t.push_back(measure_ms(o.device, c.step));
    double lo = *std::min_element(t.begin(), t.end()), hi = *std::max_element(t.begin(), t.end());
    double med = median(t);
    std::printf("%-32s %10.4f %10.4f %10.4f  %s\n", c.name.c_str(), lo, med, hi, c.detail.c_str());
    json_rows.push_back({c.name, c.detail, a.reps, lo, med, hi});
    if (c.report) std::printf("%-32s %s\n", "", c.report().c_str());
  }
  if (!a.json.empty()) {
    write_json(a.json, a.name, o.device, json_rows);
    spdlog::info("wrote {}", a.json);
  }
  return 0;
}
}  // namespace

void add_bench_command(CLI::App& app, std::function<int()>& action) {
  auto a = std::make_shared<BenchArgs>();
  auto* cmd = app.add_subcommand("bench", "run a named benchmark (warm-up, repetitions, min/median/max, JSON)");
  cmd->add_option("name", a->name, "benchmark name (seamless bench --list)");
  cmd->add_option("--reps", a->reps, "timed repetitions (default 50; pipeline: whole replays, default 1)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--warmup", a->warmup, "untimed repetitions first")->check(CLI::NonNegativeNumber);
  cmd->add_option("--device", a->device, "cpu, cuda or auto")->check(CLI::IsMember({"cpu", "cuda", "auto"}));
  cmd->add_option("--json", a->json, "write the results as JSON to this file");
  cmd->add_option("--data", a->data, "TUM folder for benchmarks over real frames");
  cmd->add_option("--filter", a->filter, "only cases whose name contains this");
  cmd->add_option("--scale", a->scale, "scene sizes for `physics`: paper (Table 5.1), large or all")
      ->check(CLI::IsMember({"paper", "large", "all"}));
  cmd->add_flag("--list", a->list, "list the benchmarks");
  cmd->add_option("--config", a->config, "pipeline: experiment file (default: every key at its default)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--set", a->sets, "pipeline: override a config key (repeatable), after the benchmark's own")
      ->allow_extra_args(false);
  cmd->add_option("--tracker", a->tracker, "pipeline: tracker.kind (icp, rgbd, ...)");
  cmd->add_option("--mode", a->mode, "pipeline: scan (seamless track) or live (seamless run, mode: live)")
      ->check(CLI::IsMember({"scan", "live"}));
  cmd->add_option("--frames", a->frames, "pipeline: replay the first N frames (default: the config's frames)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--out", a->out,
                  "pipeline: keep each replay's run folder here as rep_<k> (default: a temporary "
                  "folder, removed)");
  cmd->add_flag("--no-volume-stages", a->no_volume_stages,
                "pipeline: do not time the volume's kernel steps (allocate is then part of fuse; saves two CUDA "
                "events per step)");
  cmd->callback([&action, a] {
    action = [a] {
      if (a->list || a->name.empty()) {
        for (auto& [n, info] : bench_registry()) std::printf("%-12s %s\n", n.c_str(), info.description.c_str());
        std::printf("%-12s %s\n", "pipeline", kPipelineDescription);
        return a->list ? 0 : 2;
      }
      return run_bench(*a);
    };
  });
}

}  // namespace seamless::app
