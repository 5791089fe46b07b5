// Uses each exported library of an installed seamless once, against known answers; exits 0 when
// all hold. Built by tests/install/install_test.py against `cmake --install`'s prefix.
#include <cmath>
#include <cstdio>
#include <string>

#include "core/buffer.hpp"
#include "core/exec.hpp"
#include "eval/trajectory_eval.hpp"
#include "io/intrinsics_presets.hpp"
#include "kernels/recon/preprocess.hpp"
#include "physics/particle_solver.hpp"
#include "recon/volume.hpp"
#include "seamless/build_config.hpp"

using namespace seamless;

int main() {
  int failures = 0;
  auto check = [&](bool ok, const char* what) {
    std::printf("%s: %s\n", ok ? "ok" : "FAILED", what);
    failures += !ok;
  };
  // io: TUM's published freiburg1 calibration.
  const Intrinsics K = intrinsics_preset("freiburg1");
  check(K.fx == 517.3f && K.cy == 255.3f, "io: intrinsics_preset(freiburg1)");

  // kernels + core: a wall 2 m away back-projects to z = 2, and the pixel at the principal
  // point's column and row lies on the optical axis.
  Image<float> depth = Image<float>::from_host(std::vector<float>(64 * 48, 2.0f), 64, 48, Device::CPU);
  Image<vec3> vertices(64, 48, Device::CPU);
  Intrinsics small = K;
  small.cx = 32, small.cy = 24;
  with_exec(Device::CPU, [&]<class E>(const E& ex) {
    kernels::Preprocess<E>::depth_to_vertices(ex, depth.cview(), small, vertices.view());
  });
  const vec3 v = vertices.to_host()[24 * 64 + 32];
  check(v.z == 2.0f && std::fabs(v.x) < 1e-6f && std::fabs(v.y) < 1e-6f, "kernels: depth_to_vertices on the CPU");

  // eval: a trajectory moved 5 cm along x has no ATE after SE(3) alignment and 5 cm without.
  Trajectory gt, est;
  for (int i = 0; i < 10; ++i) {
    TumPose p;
    p.timestamp = i / 30.0;
    p.t[0] = std::sin(i * 0.3), p.t[1] = 0.1 * i, p.t[2] = std::cos(i * 0.2);
    gt.push_back(p);
    p.t[0] += 0.05;
    est.push_back(p);
  }
  EvalOptions none;
  none.align = Alignment::none;
  check(compute_ate(est, gt).trans.rmse < 1e-9 && std::fabs(compute_ate(est, gt, none).trans.rmse - 0.05) < 1e-12,
        "eval: compute_ate");

  // recon: a wall 2 m in front of the camera, fused into a TSDF volume, meshes at z = 2 (within
  // half a voxel: marching cubes interpolates the zero crossing between voxel centres).
  VolumeParams vp;
  vp.voxel_size = 0.02f, vp.truncation = 0.08f, vp.capacity = 4096, vp.hash_buckets = 1 << 12;
  auto volume = make_volume(vp, Device::CPU);
  volume->integrate(depth, Image<uchar3>(), small, SE3::identity());
  const Mesh mesh = volume->extract_mesh();
  bool on_wall = !mesh.positions.empty();
  for (vec3 p : mesh.positions) on_wall = on_wall && std::fabs(p.z - 2.0f) < 0.5f * vp.voxel_size;
  check(on_wall, "recon: make_volume, integrate, extract_mesh");

  // physics: a rigid box let go at rest falls 0.5 g t^2 = 4.9 cm in 0.1 s (semi-implicit Euler's
  // substeps add g dt_sub t / 2, under 0.5 cm at dt 0.01 s).
  SolverParams sp;
  ParticleSolver solver(sp, Device::CPU);
  SpawnParams box;
  box.kind = SpawnKind::rigid, box.position = {0.f, 1.f, 0.f}, box.size = {0.1f, 0.1f, 0.1f};
  solver.schedule({box});
  solver.spawn_next();
  auto mean_height = [&] {
    const ParticleState state = solver.download_state();
    double y = 0;
    for (vec3 x : state.x) y += x.y;
    return state.x.empty() ? 0.0 : y / static_cast<double>(state.x.size());
  };
  const double y0 = mean_height();
  for (int i = 0; i < 10; ++i) solver.step();
  check(y0 > 0.9 && std::fabs((y0 - mean_height()) - 0.0491) < 0.006,
        "physics: ParticleSolver, a rigid box in free fall");

  // build_config: the installed headers carry the version find_package(seamless) reported.
  check(std::string(SEAMLESS_VERSION) == SEAMLESS_PACKAGE_VERSION, "build_config: SEAMLESS_VERSION");
  return failures == 0 ? 0 : 1;
}
