// Kernel bodies of physics/depth_colliders.hpp. Each mirrors a loop of the host reference in
// src/physics/depth_colliders.cpp and src/app/pipeline.cpp (block_any) expression for expression,
// so that the CPU backend gives the same floats.
#pragma once
#include "kernels/physics/depth_colliders.hpp"
#include "kernels/physics/particle_math.hpp"

namespace seamless::kernels {

namespace depth_colliders_detail {
// The cell of side r holding p: floor(p / r) per axis (NearestGrid::cell of the host code).
SEAMLESS_HD inline int3 cell(vec3 p, float r) { return {floor_int(p.x / r), floor_int(p.y / r), floor_int(p.z / r)}; }
SEAMLESS_HD inline std::uint32_t key(int3 c, int bits) {
  const std::uint32_t m = (1u << bits) - 1u;
  return (static_cast<std::uint32_t>(c.x) & m) | ((static_cast<std::uint32_t>(c.y) & m) << bits) |
         ((static_cast<std::uint32_t>(c.z) & m) << (2 * bits));
}
}  // namespace depth_colliders_detail

template <Executor Exec>
void DepthColliders<Exec>::level_mask(const Exec& ex, View2D<const std::uint8_t> full, View2D<std::uint8_t> level) {
  const int sx = full.width / level.width, sy = full.height / level.height;
  ex.for_each(level.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % level.width), y = static_cast<int>(i / level.width);
    std::uint8_t any = 0;
    for (int Y = y * sy; Y < (y + 1) * sy; ++Y)
      for (int X = x * sx; X < (x + 1) * sx; ++X) any |= full(X, Y) != 0 ? 1 : 0;
    level(x, y) = any;
  });
}

template <Executor Exec>
std::int64_t DepthColliders<Exec>::used_pixels(const Exec& ex, View2D<const vec3> vertices,
                                               View2D<const std::uint8_t> mask, int* used, int* offset) {
  ex.for_each(vertices.count(), [=] SEAMLESS_HD(std::int64_t i) {
    const int x = static_cast<int>(i % vertices.width), y = static_cast<int>(i / vertices.width);
    used[i] = vertices(x, y).z > 0.f && (mask.data == nullptr || mask(x, y) != 0) ? 1 : 0;
  });
  return ex.exclusive_scan(used, offset, vertices.count());
}

template <Executor Exec>
void DepthColliders<Exec>::surface(const Exec& ex, View2D<const vec3> vertices, View2D<const vec3> normals,
                                   const int* used, const int* offset, SE3 world_T_camera, vec3* points, vec3* rays,
                                   vec3* world_normals) {
  ex.for_each(vertices.count(), [=] SEAMLESS_HD(std::int64_t i) {
    if (!used[i]) return;
    const int x = static_cast<int>(i % vertices.width), y = static_cast<int>(i / vertices.width);
    const vec3 v = vertices(x, y);
    const int s = offset[i];
    points[s] = world_T_camera * v;
    rays[s] = world_T_camera.rotate(v / length(v));
    world_normals[s] = world_T_camera.rotate(normals(x, y));
  });
}

template <Executor Exec>
void DepthColliders<Exec>::cell_keys(const Exec& ex, const vec3* p, std::int64_t n, float r, int bits,
                                     std::uint32_t* keys, int* idx) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    keys[i] = depth_colliders_detail::key(depth_colliders_detail::cell(p[i], r), bits);
    idx[i] = static_cast<int>(i);
  });
}

// The 27 cells around the point's in the host's order (z, then y, then x) and, within a cell, the
// previous points in their order (the stable sort keeps it); `<=` keeps the last of equally near
// ones, as the host does. A wrapped cell also holds far points (other cells of the same key): the
// distance test drops them (a point two cells away is more than r away), and with at least 4
// cells per axis no cell is searched twice.
template <Executor Exec>
void DepthColliders<Exec>::velocities(const Exec& ex, const vec3* points, std::int64_t n, const vec3* last,
                                      const vec3* last_normals, const int* last_sorted, const int* start, float r,
                                      int bits, float dt, vec3* velocity) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    const vec3 q = points[i];
    const int3 c = depth_colliders_detail::cell(q, r);
    int best = -1;
    float best2 = r * r;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint32_t k = depth_colliders_detail::key({c.x + dx, c.y + dy, c.z + dz}, bits);
          for (int s = start[k]; s < start[k + 1]; ++s) {
            const int j = last_sorted[s];
            const float d2 = length2(last[j] - q);
            if (d2 <= best2) best2 = d2, best = j;
          }
        }
    if (best < 0) {
      velocity[i] = {0.f, 0.f, 0.f};
      return;
    }
    const vec3 nrm = last_normals[best];
    velocity[i] = nrm * (dot(nrm, q - last[best]) / dt);
  });
}

template <Executor Exec>
void DepthColliders<Exec>::thickened(const Exec& ex, const vec3* points, const vec3* rays, const vec3* velocity,
                                     std::int64_t n, float back, float spacing, int layers, vec3* out) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    const vec3 moved = points[i] - velocity[i] * back;
    for (int k = 0; k <= layers; ++k) out[i * (layers + 1) + k] = moved + rays[i] * (spacing * static_cast<float>(k));
  });
}

// The measured surface on the particle's ray is taken at the level pixel's depth v.z (flat across
// the pixel), so the distance behind it along the ray is (z - v.z) * |q| / z.
template <Executor Exec>
InsideCount DepthColliders<Exec>::inside(const Exec& ex, const vec3* p, std::int64_t n, SE3 camera_T_world,
                                         Intrinsics K, View2D<const std::uint8_t> mask,
                                         View2D<const vec3> level_vertices, int scale, float margin, float thickness,
                                         int rest_frames, int* run) {
  ex.for_each(n, [=] SEAMLESS_HD(std::int64_t i) {
    const vec3 q = camera_T_world * p[i];
    bool in = false;
    if (q.z > 0.f) {
      const vec2 uv = K.project(q);
      const int X = floor_int(uv.x + 0.5f), Y = floor_int(uv.y + 0.5f);
      if (mask.inside(X, Y) && mask(X, Y) != 0 && level_vertices.inside(X / scale, Y / scale)) {
        const vec3 v = level_vertices(X / scale, Y / scale);
        const float behind = (q.z - v.z) * length(q) / q.z;
        in = v.z > 0.f && behind > margin && behind < thickness;
      }
    }
    run[i] = in ? run[i] + 1 : 0;
  });
  InsideCount c;
  c.inside =
      ex.transform_reduce(n, std::int64_t{0}, [=] SEAMLESS_HD(std::int64_t i) { return std::int64_t{run[i] > 0}; });
  c.resting = ex.transform_reduce(n, std::int64_t{0},
                                  [=] SEAMLESS_HD(std::int64_t i) { return std::int64_t{run[i] > rest_frames}; });
  return c;
}

}  // namespace seamless::kernels
