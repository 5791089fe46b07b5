// Benchmark scenes of the particle solver for `seamless bench physics`: the dissertation's
// Table 5.1 scenes and scaled-up ones. Each case owns its solver and steps it once per call
// (one step of params.dt with the substeps the speed limit needs; the scenes use a speed limit
// of 2 m/s, so one substep, as in the dissertation).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/device.hpp"

namespace seamless {

class ParticleSolver;

struct PhysicsBenchCase {
  std::string name;    // e.g. "fluid_10k"
  std::string detail;  // e.g. "10000 fluid particles, 2 iterations"
  std::function<void()> step;
  std::shared_ptr<ParticleSolver> solver;
};

// scale: "paper" (Table 5.1: fluid 10,000; cloth 40x40; rigid 4 x 4x4x4), "large" (fluid
// 1,000,000; cloth 512x512; 4,096 cubes of 4x4x4) or "all". On CUDA each scene comes twice: with
// the step replayed as a CUDA graph (solver.cuda_graph, the default) and as "<name>_nograph".
// Only the cases whose name contains filter are built ("" builds all).
std::vector<PhysicsBenchCase> physics_bench_cases(Device device, const std::string& scale = "all",
                                                  const std::string& filter = "");

}  // namespace seamless
