#include "render/bench_render.hpp"

#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>

#include "core/buffer.hpp"
#include "core/device.hpp"
#include "core/exec.hpp"
#include "core/mesh.hpp"
#include "core/phase.hpp"
#include "physics/fluid_ellipsoids.hpp"
#include "seamless/build_config.hpp"
#if SEAMLESS_HAS_CUDA
#include "render/cuda_interop.hpp"
#endif

namespace seamless {
namespace {

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// A floor of 4 x 4 m at y = 0 as the scene.
Mesh floor_mesh() {
  Mesh m;
  m.positions = {{-2, 0, -2}, {2, 0, -2}, {2, 0, 2}, {-2, 0, 2}};
  m.normals.assign(4, vec3{0, 1, 0});
  m.colors.assign(4, uchar3{150, 140, 120});
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

// What draw_device_particles needs besides the buffers: the particle radius. (A default DrawList
// has a radius of 0.02 m, four times the bench's: 16 times the fragments, which made the "draw
// only" figure several times the real frame's.)
DrawList device_list(float radius) {
  DrawList d;
  d.particle_radius = radius;
  return d;
}

// GPU time of a whole frame: the sum of its passes (consecutive timestamps, so first to last).
double gpu_total_ms(const std::vector<RenderTiming>& passes) {
  double t = 0.0;
  for (const RenderTiming& p : passes) t += p.ms;
  return t;
}

// Each frame: the particles copied from CUDA memory into the GL buffers, drawn, glFinish.
double interop_ms(Renderer& r, const std::vector<vec3>& x, const std::vector<std::uint32_t>& ph, float radius,
                  const RenderCamera& cam, int frames) {
#if SEAMLESS_HAS_CUDA
  if (!cuda_available()) return -1.0;
  try {
    Buffer<vec3> dx = Buffer<vec3>::from_host(x, Device::CUDA);
    Buffer<std::uint32_t> dph = Buffer<std::uint32_t>::from_host(ph, Device::CUDA);
    CudaGlParticles interop(r, static_cast<std::int64_t>(x.size()));
    std::vector<double> ms;
    for (int f = 0; f < frames; ++f) {
      auto t0 = std::chrono::steady_clock::now();
      interop.copy_from_device(dx.data(), dph.data(), static_cast<std::int64_t>(x.size()), radius);
      r.draw_device_particles(device_list(radius), static_cast<std::int64_t>(x.size()), cam);
      glFinish();
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
    return median_of(ms);
  } catch (const std::exception&) {
    return -1.0;  // GL context not on the CUDA device (e.g. Mesa): no interop here
  }
#else
  (void)r, (void)x, (void)ph, (void)radius, (void)cam, (void)frames;
  return -1.0;
#endif
}

// The anisotropic kernels' ellipsoids of the particles, computed where a run computes them (on
// CUDA when there is a device, else on the CPU), their median time over a few calls into `res`:
// the frames then time the GL passes alone. None when the renderer draws spheres.
std::vector<vec4> bench_ellipsoids(const Renderer& r, const std::vector<vec3>& x, const std::vector<std::uint32_t>& ph,
                                   float radius, RenderBenchResult& res) {
  const std::optional<Renderer::EllipsoidSizes> sizes = r.fluid_ellipsoid_sizes(radius);
  if (!sizes) return {};
  const Device d = cuda_available() ? Device::CUDA : Device::CPU;
  FluidEllipsoids shapes(d);
  const Buffer<vec3> dx = Buffer<vec3>::from_host(x, d);
  const Buffer<std::uint32_t> dph = Buffer<std::uint32_t>::from_host(ph, d);
  std::vector<double> ms;
  for (int i = 0; i < 5; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    shapes.compute(dx.data(), dph.data(), static_cast<std::int64_t>(x.size()), sizes->radius, sizes->h);
    with_exec(d, []<class E>(const E& ex) { ex.synchronize(); });
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  res.median_ellipsoid_ms = median_of(ms);
  res.ellipsoid_device = device_name(d);
  return shapes.compute_host(x, ph, sizes->radius, sizes->h);
}

}  // namespace

RenderParams unoptimised_render_settings() {
  RenderParams p;
  p.thickness_downsample = 1;
  p.depth_prepass = false;
  p.fluid_filter = FluidFilter::bilateral;
  p.filter_iterations = 2;
  p.filter_max_taps = 128;
  p.max_point_size = 2048.f;
  p.fluid_splat = FluidSplat::raster;
  return p;
}

RenderBenchResult bench_render(int width, int height, std::int64_t particles, int frames,
                               const RenderParams& settings) {
  RenderParams p = settings;
  p.width = width, p.height = height;
  p.stage_images = false;
  Renderer r(p, width, height);
  r.set_scene_mesh(floor_mesh());
  // A cube of fluid on a lattice of one diameter, standing on the floor.
  const float radius = 0.005f;
  const int side = static_cast<int>(std::ceil(std::cbrt(static_cast<double>(particles))));
  std::vector<vec3> x;
  x.reserve(static_cast<std::size_t>(particles));
  for (int k = 0; k < side && static_cast<std::int64_t>(x.size()) < particles; ++k)
    for (int j = 0; j < side && static_cast<std::int64_t>(x.size()) < particles; ++j)
      for (int i = 0; i < side && static_cast<std::int64_t>(x.size()) < particles; ++i)
        x.push_back(vec3{(i - side / 2) * 2 * radius, (j + 0.5f) * 2 * radius, (k - side / 2) * 2 * radius});
  std::vector<std::uint32_t> ph(x.size(), phase::kFluid);
  DrawList list;
  list.positions = x, list.phases = ph, list.particle_radius = radius;
  RenderBenchResult res;
  const std::vector<vec4> ellipsoids = bench_ellipsoids(r, x, ph, radius, res);
  list.ellipsoids = ellipsoids;
  const float extent = side * 2 * radius;
  RenderCamera cam = RenderCamera::look_at({extent * 0.9f, extent * 1.1f, extent * 1.3f}, {0, extent * 0.4f, 0},
                                           {0, 1, 0}, 60.f, width, height);
  r.draw(list, cam);  // warm-up: shader compilation, allocation, first upload
  glFinish();
  std::vector<double> frame_ms, read_ms, draw_ms, gpu_ms;
  std::map<std::string, std::vector<double>> pass_ms;
  using clock = std::chrono::steady_clock;
  for (int f = 0; f < frames; ++f) {
    auto t0 = clock::now();
    r.draw(list, cam);
    glFinish();
    auto t1 = clock::now();
    (void)r.read_frame();
    auto t2 = clock::now();
    frame_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    read_ms.push_back(std::chrono::duration<double, std::milli>(t2 - t1).count());
    auto t3 = clock::now();
    r.draw_device_particles(device_list(radius), static_cast<std::int64_t>(x.size()), cam);
    glFinish();
    draw_ms.push_back(std::chrono::duration<double, std::milli>(clock::now() - t3).count());
    const std::vector<RenderTiming> passes = r.last_timings();  // the draw-only frame's (done: glFinish)
    gpu_ms.push_back(gpu_total_ms(passes));
    for (const RenderTiming& t : passes) pass_ms[t.pass].push_back(t.ms);
  }
  res.median_interop_ms = interop_ms(r, x, ph, radius, cam, frames);
  res.median_gpu_ms = median_of(gpu_ms);
  res.width = width, res.height = height, res.particles = static_cast<std::int64_t>(x.size()), res.frames = frames;
  res.median_frame_ms = median_of(frame_ms);
  res.median_readback_ms = median_of(read_ms);
  res.median_draw_ms = median_of(draw_ms);
  for (const RenderTiming& t : r.last_timings()) res.passes.push_back({t.pass, median_of(pass_ms[t.pass])});
  res.gl_renderer = r.gl_info().renderer;
  return res;
}

}  // namespace seamless
