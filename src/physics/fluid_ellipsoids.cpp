#include "physics/fluid_ellipsoids.hpp"

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/phase.hpp"
#include "kernels/physics/anisotropy.hpp"
#include "kernels/physics/grid.hpp"

namespace seamless {

namespace K = kernels;

FluidEllipsoids::FluidEllipsoids(Device d) : dev_(d) {}

const vec4* FluidEllipsoids::compute(const vec3* x, const std::uint32_t* phase, std::int64_t n, float radius, float h) {
  if (!(radius > 0.f) || !(h > 0.f))
    throw Error("fluid ellipsoids: radius " + std::to_string(radius) + " and neighbourhood " + std::to_string(h) +
                " must be positive");
  out_.reserve_discard(std::max<std::int64_t>(n, 1) * K::kEllipsoidVec4s, dev_);
  if (n == 0) return out_.data();
  const int bits = K::GridSpec::bits_for(n);
  const std::int64_t cells = std::int64_t{1} << (3 * bits);
  keys_.reserve_discard(n, dev_), id_.reserve_discard(n, dev_), sorted_.reserve_discard(n, dev_);
  cell_start_.reserve_discard(cells + 1, dev_);
  K::EllipsoidViews V;
  V.n = n, V.sorted = sorted_.data(), V.id = id_.data(), V.grid = K::GridSpec::for_radius(h, bits);
  V.cell_start = cell_start_.data(), V.fluid_mask = phase::kFluid, V.radius = radius, V.h = h;
  V.ellipsoids = out_.data();
  with_exec(dev_, [&]<class E>(const E& ex) {
    using Grid = K::NeighbourGrid<E>;
    Grid::cell_keys(ex, x, n, V.grid, keys_.data(), id_.data());
    Grid::sort_cells(ex, keys_.data(), id_.data(), n, 3 * bits);
    Grid::cell_starts(ex, keys_.data(), n, cell_start_.data(), cells);
    K::Anisotropy<E>::pack(ex, x, phase, id_.data(), n, sorted_.data());
    K::Anisotropy<E>::ellipsoids(ex, V);
  });
  return out_.data();
}

std::vector<vec4> FluidEllipsoids::compute_host(const std::vector<vec3>& x, const std::vector<std::uint32_t>& phase,
                                                float radius, float h) {
  if (phase.size() != x.size())
    throw Error("fluid ellipsoids: " + std::to_string(x.size()) + " positions but " + std::to_string(phase.size()) +
                " phases");
  const auto n = static_cast<std::int64_t>(x.size());
  const vec3* px = x.data();
  const std::uint32_t* pp = phase.data();
  if (dev_ != Device::CPU) {
    x_ = Buffer<vec3>::from_host(x, dev_), phase_ = Buffer<std::uint32_t>::from_host(phase, dev_);
    px = x_.data(), pp = phase_.data();
  }
  compute(px, pp, n, radius, h);
  std::vector<vec4> out = out_.to_host();
  out.resize(static_cast<std::size_t>(n) * K::kEllipsoidVec4s);
  return out;
}

}  // namespace seamless
