#include "app/bench.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>

#include "app/bench_cases.hpp"
#include "core/timing.hpp"

namespace seamless::app {

std::map<std::string, BenchInfo>& bench_registry() {
  static std::map<std::string, BenchInfo> r;
  return r;
}

void register_benchmarks() {
  bench_registry()["preprocess"] = {"bilateral filter, 3-level depth pyramid, vertex and normal maps at 640x480",
                                    make_preprocess_bench};
}

}  // namespace seamless::app
