// `seamless bench <name>`: named benchmarks. Each factory builds its cases (inputs uploaded,
// buffers allocated) and returns one callable per case; the runner warms up, repeats, times each
// call with measure_ms (CUDA events / steady clock), prints min/median/max and writes JSON.
#pragma once
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/device.hpp"

namespace seamless::app {

struct BenchCase {
  std::string name;
  std::function<void()> step;
  std::string detail;                        // e.g. "640x480, 3 levels"
  std::function<std::string()> report = {};  // extra figures after the timing (blocks, counts)
};

struct BenchOptions {
  Device device = Device::CPU;
  std::string data_dir;       // TUM folder for benchmarks on real frames ("" = synthetic input)
  std::string filter;         // run only cases whose name contains this
  std::string scale = "all";  // benchmarks with sized scenes: paper (the dissertation's), large, all
};

using BenchFactory = std::function<std::vector<BenchCase>(const BenchOptions&)>;

struct BenchInfo {
  std::string description;
  BenchFactory factory;
  // A benchmark that times itself (e.g. with GL timer queries) prints its own table instead; it
  // gets the repetition count and the JSON path ("" = none).
  std::function<int(const BenchOptions&, int reps, const std::string& json)> custom = {};
};

std::map<std::string, BenchInfo>& bench_registry();

// Registers the benchmarks this build contains (called once from main).
void register_benchmarks();

}  // namespace seamless::app
