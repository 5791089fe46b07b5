#include "physics/depth_colliders.hpp"

#include <cmath>
#include <string>
#include <unordered_map>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/physics/depth_colliders.hpp"
#include "kernels/physics/grid.hpp"

namespace seamless {

DepthSurface depth_surface(const std::vector<vec3>& camera_vertices, const std::vector<vec3>& camera_normals, int width,
                           int height, const SE3& world_T_camera, const std::vector<std::uint8_t>& mask) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (camera_vertices.size() != n || camera_normals.size() != n || (!mask.empty() && mask.size() != n))
    throw Error("depth colliders: a " + std::to_string(width) + "x" + std::to_string(height) +
                " view needs that many vertices (got " + std::to_string(camera_vertices.size()) + "), normals (got " +
                std::to_string(camera_normals.size()) + ") and mask bytes (got " + std::to_string(mask.size()) + ")");
  DepthSurface s;
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 v = camera_vertices[i];
    if (!(v.z > 0.f) || (!mask.empty() && mask[i] == 0)) continue;
    s.points.push_back(world_T_camera * v);
    s.rays.push_back(world_T_camera.rotate(v / length(v)));
    s.normals.push_back(world_T_camera.rotate(camera_normals[i]));
  }
  return s;
}

std::vector<vec3> thicken(const std::vector<vec3>& points, const std::vector<vec3>& rays, float spacing,
                          float thickness) {
  if (!(spacing > 0.f)) throw Error("depth colliders: the spacing must be positive");
  const int layers = thickness > 0.f ? static_cast<int>(std::floor(thickness / spacing)) : 0;
  std::vector<vec3> out;
  out.reserve(points.size() * static_cast<std::size_t>(layers + 1));
  for (std::size_t i = 0; i < points.size(); ++i)
    for (int k = 0; k <= layers; ++k) out.push_back(points[i] + rays[i] * (spacing * static_cast<float>(k)));
  return out;
}

namespace {

// Nearest point of `pts` within r of q (index, or -1), through a hash of cells of side r.
class NearestGrid {
 public:
  NearestGrid(const std::vector<vec3>& pts, float r) : pts_(pts), r_(r) {
    for (std::size_t i = 0; i < pts.size(); ++i) cells_[key(cell(pts[i]))].push_back(static_cast<int>(i));
  }
  int nearest(vec3 q) const {
    const int3 c = cell(q);
    int best = -1;
    float best2 = r_ * r_;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = cells_.find(key({c.x + dx, c.y + dy, c.z + dz}));
          if (it == cells_.end()) continue;
          for (int i : it->second) {
            const float d2 = length2(pts_[static_cast<std::size_t>(i)] - q);
            if (d2 <= best2) best2 = d2, best = i;
          }
        }
    return best;
  }

 private:
  int3 cell(vec3 p) const {
    return {static_cast<int>(std::floor(p.x / r_)), static_cast<int>(std::floor(p.y / r_)),
            static_cast<int>(std::floor(p.z / r_))};
  }
  static std::uint64_t key(int3 c) {
    return (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.x) & 0x1fffff) << 42) |
           (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.y) & 0x1fffff) << 21) |
           (static_cast<std::uint64_t>(static_cast<std::uint32_t>(c.z) & 0x1fffff));
  }
  const std::vector<vec3>& pts_;
  float r_;
  std::unordered_map<std::uint64_t, std::vector<int>> cells_;
};

}  // namespace

void MovingColliders::update(DepthSurface surface, double t) {
  velocity_.assign(surface.points.size(), vec3{0.f, 0.f, 0.f});
  const double dt = t - time_;
  if (have_ && dt > 0.0 && !last_.points.empty()) {
    const float r = static_cast<float>(max_speed_ * dt);
    const NearestGrid grid(last_.points, r);
    for (std::size_t i = 0; i < surface.points.size(); ++i) {
      const int j = grid.nearest(surface.points[i]);
      if (j < 0) continue;
      const vec3 n = last_.normals[static_cast<std::size_t>(j)];
      velocity_[i] =
          n * (dot(n, surface.points[i] - last_.points[static_cast<std::size_t>(j)]) / static_cast<float>(dt));
    }
  }
  last_ = std::move(surface);
  time_ = t;
  have_ = true;
}

std::vector<vec3> MovingColliders::at(double t) const {
  std::vector<vec3> moved = last_.points;  // the points only: rays and normals are not copied
  const float back = static_cast<float>(time_ - t);
  for (std::size_t i = 0; i < moved.size(); ++i) moved[i] -= velocity_[i] * back;
  return thicken(moved, last_.rays, spacing_, thickness_);
}

DeviceColliders::DeviceColliders(float spacing, float thickness, float max_speed, Device d)
    : spacing_(spacing), thickness_(thickness), max_speed_(max_speed), dev_(d) {
  if (!(spacing > 0.f)) throw Error("depth colliders: the spacing must be positive");
}

void DeviceColliders::update(const Image<vec3>& camera_vertices, const Image<vec3>& camera_normals,
                             const SE3& world_T_camera, const Image<std::uint8_t>* full_mask, double t) {
  const int w = camera_vertices.width(), h = camera_vertices.height();
  const std::int64_t n = std::int64_t{w} * h;
  if (camera_normals.width() != w || camera_normals.height() != h)
    throw Error("depth colliders: a " + std::to_string(w) + "x" + std::to_string(h) + " vertex map with a " +
                std::to_string(camera_normals.width()) + "x" + std::to_string(camera_normals.height()) + " normal map");
  if (full_mask && full_mask->width() > 0 && (full_mask->width() < w || full_mask->height() < h))
    throw Error("depth colliders: a " + std::to_string(full_mask->width()) + "x" + std::to_string(full_mask->height()) +
                " dynamic mask is smaller than the " + std::to_string(w) + "x" + std::to_string(h) + " maps");
  std::swap(points_, last_points_), std::swap(rays_, last_rays_), std::swap(normals_, last_normals_);
  last_count_ = count_;
  used_.reserve_discard(n, dev_), offset_.reserve_discard(n, dev_);
  with_exec(dev_, [&]<class E>(const E& ex) {
    using DC = kernels::DepthColliders<E>;
    View2D<const std::uint8_t> mask{};  // null: every pixel
    if (full_mask) {
      level_mask_.reserve_discard(n, dev_);
      const View2D<std::uint8_t> level{level_mask_.data(), w, h, w};
      if (full_mask->width() > 0) DC::level_mask(ex, full_mask->cview(), level);
      else level_mask_.zero();  // no mask yet (the first frame): nothing is dynamic
      mask = level;
    }
    count_ = DC::used_pixels(ex, camera_vertices.cview(), mask, used_.data(), offset_.data());
    points_.reserve_discard(count_, dev_), rays_.reserve_discard(count_, dev_), normals_.reserve_discard(count_, dev_);
    DC::surface(ex, camera_vertices.cview(), camera_normals.cview(), used_.data(), offset_.data(), world_T_camera,
                points_.data(), rays_.data(), normals_.data());
  });
  velocity_.reserve_discard(count_, dev_);
  velocity_.zero();
  const double dt = t - time_;
  if (have_ && dt > 0.0 && last_count_ > 0 && count_ > 0) estimate_velocities(dt);
  time_ = t;
  have_ = true;
}

// MovingColliders::update's search: the previous points sorted by cell of side max_speed * dt
// (2^bits per axis, at least 4 so that the 27 cells searched are distinct, about one per point).
void DeviceColliders::estimate_velocities(double dt) {
  const float r = static_cast<float>(max_speed_ * dt);
  int bits = 2;
  while (bits < 7 && (std::int64_t{1} << (3 * bits)) < last_count_) ++bits;
  const std::int64_t cells = std::int64_t{1} << (3 * bits);
  keys_.reserve_discard(last_count_, dev_), idx_.reserve_discard(last_count_, dev_);
  start_.reserve_discard(cells + 1, dev_);
  with_exec(dev_, [&]<class E>(const E& ex) {
    using DC = kernels::DepthColliders<E>;
    using Grid = kernels::NeighbourGrid<E>;
    DC::cell_keys(ex, last_points_.data(), last_count_, r, bits, keys_.data(), idx_.data());
    Grid::sort_cells(ex, keys_.data(), idx_.data(), last_count_, 3 * bits);
    Grid::cell_starts(ex, keys_.data(), last_count_, start_.data(), cells);
    DC::velocities(ex, points_.data(), count_, last_points_.data(), last_normals_.data(), idx_.data(), start_.data(), r,
                   bits, static_cast<float>(dt), velocity_.data());
  });
}

std::int64_t DeviceColliders::at(double t) {
  const int layers = thickness_ > 0.f ? static_cast<int>(std::floor(thickness_ / spacing_)) : 0;
  const std::int64_t total = count_ * (layers + 1);
  out_.reserve_discard(total, dev_);
  const float back = static_cast<float>(time_ - t);
  with_exec(dev_, [&]<class E>(const E& ex) {
    kernels::DepthColliders<E>::thickened(ex, points_.data(), rays_.data(), velocity_.data(), count_, back, spacing_,
                                          layers, out_.data());
  });
  return total;
}

}  // namespace seamless
