#include "physics/depth_colliders.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "kernels/physics/depth_colliders.hpp"
#include "kernels/physics/grid.hpp"

namespace seamless {

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

// The velocities' search: the previous points sorted by cell of side max_speed * dt
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

InsidePeopleCheck::InsidePeopleCheck(float margin, float thickness, int rest_frames, Device d) : dev_(d) {
  if (!(margin >= 0.f) || !(thickness > margin))
    throw Error("inside-people check: the margin " + std::to_string(margin) + " m must be in [0, the thickness " +
                std::to_string(thickness) + " m)");
  stats_.margin = margin, stats_.thickness = thickness, stats_.rest_frames = rest_frames;
}

kernels::InsideCount InsidePeopleCheck::check(const vec3* p, std::int64_t n, const SE3& world_T_camera,
                                              const Intrinsics& K, const Image<std::uint8_t>& mask,
                                              const Image<vec3>& level_vertices, std::int64_t frame) {
  if (n > run_.size()) {  // new particles spawned: they start outside
    Buffer<int> grown(n, dev_);
    grown.zero();
    grown.copy_from(run_);
    run_ = std::move(grown);
  }
  kernels::InsideCount c;
  const int w = level_vertices.width();
  if (n > 0 && mask.width() > 0 && w > 0) {
    if (mask.width() % w != 0 || mask.width() / w * level_vertices.height() != mask.height())
      throw Error("inside-people check: a " + std::to_string(mask.width()) + "x" + std::to_string(mask.height()) +
                  " mask is not a whole number of " + std::to_string(w) + "x" +
                  std::to_string(level_vertices.height()) + " level pixels");
    with_exec(dev_, [&]<class E>(const E& ex) {
      c = kernels::DepthColliders<E>::inside(ex, p, n, world_T_camera.inverse(), K, mask.cview(),
                                             level_vertices.cview(), mask.width() / w, stats_.margin, stats_.thickness,
                                             stats_.rest_frames, run_.data());
    });
  } else if (n > 0) {
    run_.zero();  // no mask this frame: nobody seen, every run ends
  }
  ++stats_.frames_checked;
  if (c.inside > stats_.max_inside) stats_.max_inside = c.inside, stats_.max_inside_frame = frame;
  if (c.resting > 0) ++stats_.frames_resting;
  stats_.max_resting = std::max(stats_.max_resting, c.resting);
  return c;
}

}  // namespace seamless
