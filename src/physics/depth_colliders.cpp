#include "physics/depth_colliders.hpp"

#include <cmath>
#include <string>

#include "core/error.hpp"

namespace seamless {

std::vector<vec3> depth_collider_points(const std::vector<vec3>& camera_vertices, int width, int height,
                                        const SE3& world_T_camera, float spacing, float thickness,
                                        const std::vector<std::uint8_t>& mask) {
  const std::size_t n = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (camera_vertices.size() != n || (!mask.empty() && mask.size() != n))
    throw Error("depth_collider_points: a " + std::to_string(width) + "x" + std::to_string(height) +
                " view needs that many vertices (got " + std::to_string(camera_vertices.size()) +
                ") and mask bytes (got " + std::to_string(mask.size()) + ")");
  if (!(spacing > 0.f)) throw Error("depth_collider_points: the spacing must be positive");
  const int layers = thickness > 0.f ? static_cast<int>(std::floor(thickness / spacing)) : 0;
  std::vector<vec3> out;
  for (std::size_t i = 0; i < n; ++i) {
    const vec3 v = camera_vertices[i];
    if (!(v.z > 0.f) || (!mask.empty() && mask[i] == 0)) continue;
    const vec3 p = world_T_camera * v;
    const vec3 ray = world_T_camera.rotate(v / length(v));  // from the camera through the point
    for (int k = 0; k <= layers; ++k) out.push_back(p + ray * (spacing * static_cast<float>(k)));
  }
  return out;
}

}  // namespace seamless
