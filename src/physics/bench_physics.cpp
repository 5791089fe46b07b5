#include "physics/bench_physics.hpp"

#include <cmath>

#include "physics/particle_solver.hpp"

namespace seamless {

namespace {

SolverParams bench_params(std::int64_t capacity, bool graph) {
  SolverParams p;
  p.cuda_graph = graph;
  p.max_speed = 2.f;  // one substep at dt = 0.01 s, d = 0.04 m
  p.max_particles = capacity;
  return p;
}

kernels::SceneSdf floor_box(float half) {
  kernels::SceneSdf s;
  s.count = 1;
  s.prims[0] = {kernels::kSdfContainer, {0.f, 10.f, 0.f}, {half, 10.f, half}, mat3::identity()};
  return s;
}

PhysicsBenchCase make_case(const std::string& name, const std::string& detail, std::shared_ptr<ParticleSolver> s) {
  for (int i = 0; i < 5; ++i) s->step();  // past the first allocations and contacts
  return {name, detail, [s] { s->step(); }, s};
}

PhysicsBenchCase fluid(Device dev, bool graph, const std::string& name, int nx, int ny, int nz) {
  auto s = std::make_shared<ParticleSolver>(bench_params(std::int64_t{nx} * ny * nz, graph), dev);
  const float d = s->params().particle_diameter;
  s->set_scene_sdf(floor_box(0.5f * nx * d + 0.2f));
  SpawnParams f;
  f.kind = SpawnKind::fluid_block, f.size = {nx * d, ny * d, nz * d}, f.position = {0.f, 0.5f * ny * d + 0.01f, 0.f};
  s->spawn(f);
  return make_case(name, std::to_string(s->size()) + " fluid particles, 2 iterations", s);
}

PhysicsBenchCase cloth(Device dev, bool graph, const std::string& name, int n) {
  auto s = std::make_shared<ParticleSolver>(bench_params(std::int64_t{n} * n, graph), dev);
  s->set_scene_sdf(floor_box(0.05f * n + 1.f));
  SpawnParams c;
  c.kind = SpawnKind::cloth, c.nx = n, c.ny = n, c.position = {0.f, 1.f, 0.f}, c.pinned = {0, 1};
  s->spawn(c);
  return make_case(name, std::to_string(n) + "x" + std::to_string(n) + " cloth, 2 iterations", s);
}

PhysicsBenchCase rigid(Device dev, bool graph, const std::string& name, int bodies) {
  auto s = std::make_shared<ParticleSolver>(bench_params(std::int64_t{bodies} * 64, graph), dev);
  const float d = s->params().particle_diameter;
  int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(bodies))));
  s->set_scene_sdf(floor_box(0.5f * side * 6 * d + 0.5f));
  for (int b = 0; b < bodies; ++b) {
    SpawnParams c;
    c.kind = SpawnKind::rigid, c.size = {4 * d, 4 * d, 4 * d};
    c.position = {(b % side - 0.5f * side) * 6 * d, 0.1f + 0.3f * (b / (side * side)),
                  (b / side % side - 0.5f * side) * 6 * d};
    s->spawn(c);
  }
  return make_case(name, std::to_string(bodies) + " rigid cubes of 4x4x4 particles, 2 iterations", s);
}

}  // namespace

std::vector<PhysicsBenchCase> physics_bench_cases(Device dev, const std::string& scale, const std::string& filter) {
  std::vector<PhysicsBenchCase> out;
  // Only the scenes the filter selects are built (a 1M-particle scene takes seconds and GBs).
  auto add = [&](const std::string& name, auto&& make) {
    if (filter.empty() || name.find(filter) != std::string::npos) out.push_back(make(name));
  };
  // On CUDA every scene also runs without graphs ("_nograph"), to compare (solver.cuda_graph).
  for (bool graph : {true, false}) {
    if (!graph && dev != Device::CUDA) break;
    const std::string tag = graph ? "" : "_nograph";
    if (scale == "paper" || scale == "all") {
      add("fluid_10k" + tag, [&](const std::string& n) { return fluid(dev, graph, n, 25, 16, 25); });  // 10,000
      add("cloth_40x40" + tag, [&](const std::string& n) { return cloth(dev, graph, n, 40); });
      add("rigid_4" + tag, [&](const std::string& n) { return rigid(dev, graph, n, 4); });
    }
    if (scale == "large" || scale == "all") {
      add("fluid_1m" + tag, [&](const std::string& n) { return fluid(dev, graph, n, 100, 100, 100); });
      add("cloth_512x512" + tag, [&](const std::string& n) { return cloth(dev, graph, n, 512); });
      add("rigid_4096" + tag, [&](const std::string& n) { return rigid(dev, graph, n, 4096); });
    }
  }
  return out;
}

}  // namespace seamless
