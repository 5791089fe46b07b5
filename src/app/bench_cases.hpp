// Factories of the benchmarks registered in bench.cpp, one per pipeline part.
#pragma once
#include "app/bench.hpp"

namespace seamless::app {
std::vector<BenchCase> make_preprocess_bench(const BenchOptions& o);
std::vector<BenchCase> make_recon_bench(const BenchOptions& o);
std::vector<BenchCase> make_physics_bench(const BenchOptions& o);
std::vector<BenchCase> make_tracking_bench(const BenchOptions& o);
int run_render_bench(const BenchOptions& o, int reps, const std::string& json);
}  // namespace seamless::app
