// `seamless bench pipeline`: a real sequence replayed once, in order, through the code of
// `seamless track` (scan mode: app::scan) or of `seamless run` in live mode (app::live), each
// frame once and the volume growing as in a run; per-stage and per-frame median, p90 and max.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/device.hpp"

namespace seamless::app {

struct PipelineBenchOptions {
  std::string data;               // TUM folder (input.source: tum); "" = the config's input
  std::string config;             // experiment file; "" = every key at its default
  std::vector<std::string> sets;  // --set overrides, applied last
  std::string tracker;            // tracker.kind; "" = the config's
  std::string mode = "scan";      // scan (seamless track) or live (seamless run, mode: live)
  std::int64_t frames = 0;        // 0 = the config's `frames` (0: every frame of the input)
  int reps = 1;                   // whole replays, each with a fresh volume (and solver)
  Device device = Device::CPU;
  std::string out;            // run folders rep_<k> go here; "" = a temporary folder, removed after
  std::string json;           // "" = no JSON
  bool volume_stages = true;  // time the volume's kernel steps (allocate apart from fuse)
};

int run_pipeline_bench(const PipelineBenchOptions& o);

}  // namespace seamless::app
