// Ghost measures: how much of what moved stays in the map after it has gone.
// - ghost_vertices (summary.json `dynamic.ghost_vertices`): against the synthetic room's movers'
//   exact geometry, so only for `input.source: synthetic` with `input.synthetic.movers`.
// - seen_through_vertices (summary.json `ghost`): against the run's own depth maps, any source:
//   mesh vertices in space that the frames saw through (a reading well behind them).
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/buffer.hpp"
#include "core/intrinsics.hpp"
#include "core/mesh.hpp"
#include "io/input_params.hpp"
#include "io/trajectory.hpp"

namespace seamless {

struct GhostCount {
  std::int64_t total = 0;
  std::vector<std::int64_t> by_mover;  // index: mover id - 1 (input.synthetic.movers' order)
};

// Mesh vertices (world frame of the run) inside any mover's capsules at any of the ground truth's
// timestamps by more than `margin`, that do not lie within `margin` of the room's own surface (the
// floor a person's feet stand on, a wall an arm reaches into); each counts for the mover of the
// nearest capsule at the first timestamp it is inside one. The mesh is taken to the room frame
// of groundtruth.txt by the first pose: world_T_room = estimate(t0) * groundtruth(t0)^-1 at the
// first timestamp both have. None without movers or without a common timestamp.
std::optional<GhostCount> ghost_vertices(const Mesh& mesh, const InputParams& in, const Trajectory& estimate,
                                         const Trajectory& groundtruth, float margin);

// The depth maps of a run's fused frames, every `step`-th pixel of every `step`-th row, each with
// its pose (world_T_camera, the pose it was fused with) and its intrinsics: what the frames saw,
// kept to check the mesh against. 640x480 at step 4: 77 KB a frame.
class SeenViews {
 public:
  explicit SeenViews(int step = 4) : step_(step) {}
  // depth: host image, metres, 0 = no reading (RgbdFrame::depth, undistorted, before any masking:
  // a person's own readings see through the space in front of them too).
  void add(const Image<float>& depth, const Intrinsics& K, const SE3& world_T_camera);
  std::size_t size() const { return views_.size(); }

  struct View {
    std::vector<float> depth;  // (width / step) x (height / step)
    int w = 0, h = 0;
    Intrinsics K;  // of the full-resolution frame
    SE3 camera_T_world;
  };
  const std::vector<View>& views() const { return views_; }
  int step() const { return step_; }

 private:
  int step_;
  std::vector<View> views_;
};

struct SeenThroughGhost {
  std::int64_t vertices = 0;       // mesh vertices seen through by at least min_views views
  std::int64_t mesh_vertices = 0;  // of the mesh
  std::int64_t views = 0;          // views the mesh was checked against
  double fraction() const { return mesh_vertices > 0 ? double(vertices) / double(mesh_vertices) : 0.0; }
};

// The depth noise the seen-through test allows for: a static surface's reading lies within
// 3 sigma(z) of it (structured light, sigma = 1.5e-3 z^2 m, Khoshelham & Elberink 2012) plus
// `slack` for the mesh's own offset (the TSDF's zero crossing, a voxel or two) and the pose error.
inline float seen_through_margin(float z, float slack) { return slack + 3.f * 1.5e-3f * z * z; }

// Mesh vertices (the run's world frame) that at least `min_views` of `views` saw through: the vertex
// projects into the view in front of the camera and every reading of the 3x3 kept pixels around its
// projection lies behind it by more than seen_through_margin (all nine: a vertex on a static edge is
// never seen through by a neighbouring pixel that saw past the edge, and a pixel without a reading
// is no evidence). A static surface the frames saw is never seen through; what a person left in the
// map is, by every frame that saw the room behind where they stood. At most max_views views are
// used, spread evenly over the run (the cost is vertices x views).
SeenThroughGhost seen_through_vertices(const Mesh& mesh, const SeenViews& views, float slack, int min_views = 2,
                                       int max_views = 150);

}  // namespace seamless
