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

}  // namespace seamless
