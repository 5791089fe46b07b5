// `seamless bench physics`: one solver step of the dissertation's Table 5.1 scenes and of the
// scaled ones (src/physics/bench_physics.hpp builds them). --scale paper|large picks a set.
#include "app/bench_cases.hpp"
#include "physics/bench_physics.hpp"
#include "physics/particle_solver.hpp"

namespace seamless::app {

std::vector<BenchCase> make_physics_bench(const BenchOptions& o) {
  std::vector<BenchCase> cases;
  for (PhysicsBenchCase& c : physics_bench_cases(o.device, o.scale, o.filter)) {
    auto solver = c.solver;
    cases.push_back({c.name, c.step, c.detail, [solver] {
                       auto s = solver->stats();
                       return "particles " + std::to_string(s.particles) + ", substeps " + std::to_string(s.substeps);
                     }});
  }
  return cases;
}

}  // namespace seamless::app
