#include "host_colliders.hpp"

#include <cmath>
#include <string>
#include <unordered_map>

#include "core/error.hpp"

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

}  // namespace seamless
