#include "app/ghost.hpp"

#include <algorithm>
#include <cmath>

#include "io/movers.hpp"
#include "kernels/scene/synthetic_room.hpp"

namespace seamless {

namespace {

// The first pose of `a` whose timestamp `b` also has (within a tenth of a 30 Hz frame).
std::optional<std::pair<SE3, SE3>> first_common_pose(const Trajectory& a, const Trajectory& b) {
  for (const TumPose& p : a)
    for (const TumPose& q : b)
      if (std::fabs(p.timestamp - q.timestamp) < 0.0033) return std::make_pair(p.se3(), q.se3());
  return std::nullopt;
}

}  // namespace

std::optional<GhostCount> ghost_vertices(const Mesh& mesh, const InputParams& in, const Trajectory& estimate,
                                         const Trajectory& groundtruth, float margin) {
  if (in.source != InputSource::synthetic || in.synthetic.movers.empty()) return std::nullopt;
  const auto poses = first_common_pose(estimate, groundtruth);
  if (!poses) return std::nullopt;
  const SE3 room_T_world = poses->second * poses->first.inverse();
  // The movers at every frame, and the box around all of them: most of the room is outside it.
  std::vector<kernels::movers::Scene> track;
  vec3 lo{1e30f, 1e30f, 1e30f}, hi{-1e30f, -1e30f, -1e30f};
  for (const TumPose& g : groundtruth) {
    const kernels::movers::Scene s = pose_movers(in.synthetic.movers, g.timestamp);
    if (s.count == 0) continue;
    for (int i = 0; i < s.count; ++i) {
      const float r = s.c[i].r;
      const vec3 a = s.c[i].a, b = s.c[i].b;
      lo = {std::min({lo.x, a.x - r, b.x - r}), std::min({lo.y, a.y - r, b.y - r}), std::min({lo.z, a.z - r, b.z - r})};
      hi = {std::max({hi.x, a.x + r, b.x + r}), std::max({hi.y, a.y + r, b.y + r}), std::max({hi.z, a.z + r, b.z + r})};
    }
    track.push_back(s);
  }
  GhostCount ghost;
  ghost.by_mover.assign(in.synthetic.movers.size(), 0);
  for (const vec3& v : mesh.positions) {
    const vec3 q = room_T_world * v;
    if (q.x < lo.x || q.y < lo.y || q.z < lo.z || q.x > hi.x || q.y > hi.y || q.z > hi.z) continue;
    if (std::fabs(kernels::room::room_sdf(q)) < margin) continue;
    for (const kernels::movers::Scene& s : track) {
      int nearest = 0;
      if (kernels::movers::distance(s, q, &nearest) < -margin) {
        ++ghost.total;
        ++ghost.by_mover.at(static_cast<std::size_t>(s.c[nearest].mover - 1));
        break;
      }
    }
  }
  return ghost;
}

void SeenViews::add(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera) {
  View v;
  v.w = depth.width() / step_, v.h = depth.height() / step_;
  v.K = K, v.camera_T_world = world_T_camera.inverse();
  const std::vector<float> full = depth.to_host();
  v.depth.resize(static_cast<std::size_t>(v.w) * static_cast<std::size_t>(v.h));
  for (int y = 0; y < v.h; ++y)
    for (int x = 0; x < v.w; ++x)
      v.depth[static_cast<std::size_t>(y) * v.w + x] =
          full[static_cast<std::size_t>(y * step_) * static_cast<std::size_t>(depth.width()) + x * step_];
  views_.push_back(std::move(v));
}

namespace {

// Whether `view` saw through the world point p (seen_through_vertices' rule).
bool sees_through(const SeenViews::View& view, int step, vec3 p, float slack) {
  const vec3 c = view.camera_T_world * p;
  if (c.z < 0.1f) return false;
  // The kept pixel (x, y) holds the reading of full-resolution pixel (step x, step y).
  const float u = (view.K.fx * c.x / c.z + view.K.cx) / static_cast<float>(step);
  const float v = (view.K.fy * c.y / c.z + view.K.cy) / static_cast<float>(step);
  const int x = static_cast<int>(std::lround(u)), y = static_cast<int>(std::lround(v));
  if (x < 1 || y < 1 || x >= view.w - 1 || y >= view.h - 1) return false;
  const float behind = c.z + seen_through_margin(c.z, slack);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) {
      const float d = view.depth[static_cast<std::size_t>(y + dy) * view.w + (x + dx)];
      if (!(d > behind)) return false;  // no reading (0), or a reading at or in front of the vertex
    }
  return true;
}

}  // namespace

SeenThroughGhost seen_through_vertices(const Mesh& mesh, const SeenViews& views, float slack, int min_views,
                                       int max_views) {
  SeenThroughGhost g;
  g.mesh_vertices = static_cast<std::int64_t>(mesh.positions.size());
  const auto& all = views.views();
  std::vector<const SeenViews::View*> used;
  const std::size_t n = all.size(), m = std::min<std::size_t>(n, static_cast<std::size_t>(std::max(1, max_views)));
  for (std::size_t i = 0; i < m; ++i) used.push_back(&all[i * n / m]);  // evenly spread, the first included
  g.views = static_cast<std::int64_t>(used.size());
  std::int64_t count = 0;
  const auto nv = static_cast<std::int64_t>(mesh.positions.size());
#pragma omp parallel for reduction(+ : count) schedule(static, 4096)
  for (std::int64_t i = 0; i < nv; ++i) {
    int seen = 0;
    for (const SeenViews::View* v : used)
      if (sees_through(*v, views.step(), mesh.positions[static_cast<std::size_t>(i)], slack) && ++seen >= min_views)
        break;
    if (seen >= min_views) ++count;
  }
  g.vertices = count;
  return g;
}

}  // namespace seamless
