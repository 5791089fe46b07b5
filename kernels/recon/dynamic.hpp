// Dynamic pixels from depth alone (docs/DYNAMIC.md): which pixels of a frame see
// something that moves (a person walking, a ball rolling), found by comparing the measurement with
// the model raycast, after ReFusion (Palazzolo et al., "ReFusion: 3D Reconstruction in Dynamic
// Environments for RGB-D Cameras Exploiting Residuals", IROS 2019, sections III-C and III-D):
// a large residual against the model and a measurement well in front of a model surface along its
// ray (free-space violation), then region and temporal consistency so that noise makes no speckles.
// Masks are 0 (static) / 1 (dynamic), one byte a pixel.
#pragma once
#include <cstdint>

#include "core/exec.hpp"
#include "core/intrinsics.hpp"
#include "core/math.hpp"
#include "core/view.hpp"
#include "kernels/recon/voxel_hash.hpp"

namespace seamless::kernels {

// What classify_dynamic compares: the frame's depth and the model raycast, both seen by the same
// pinhole camera K; the model in the coordinates of the camera it was rendered from (ref), the
// frame at ref_T_cur (the predicted pose before tracking, the tracked pose after).
struct DynamicInput {
  View2D<const float> depth;  // metres, 0 = no reading (the filtered level 0)
  Intrinsics K;
  View2D<const vec3> model_vertices;  // reference camera coordinates, zero = no surface
  View2D<const vec3> model_normals;   // facing the reference camera, zero = none
  SE3 ref_T_cur;
  float residual_min = 0.03f;   // metres: the residual threshold's floor (tracking and raycast error)
  float noise_coeff = 0.0015f;  // depth noise sigma(z) = noise_coeff * z^2 (Khoshelham & Elberink 2012)
  float residual_sigmas = 3.f;  // the residual threshold in noise sigmas
  float free_space = 0.12f;     // metres in front of the nearest model surface along the ray
  int search_radius = 2;        // pixels around the projection searched for the best-fitting model point
  // Kinect v1 triangulation: disparity d = f b / z measured in 1/8-pixel steps (baseline b 7.5 cm;
  // Khoshelham & Elberink 2012, Konolige & Mihelich 2010), so depths come in steps of
  // dz = z^2 * disparity_step / (f b) (src/io/depth_scale.cpp; the synthetic sensor quantises the
  // same way with the frame's own fx). Pixels per metre of baseline; 0: no quantisation.
  float disparity_step_per_baseline = 0.125f / 0.075f;
  // free_space_evidence views: a pixel with a reading and no model surface near its projection is
  // 2 (undecided: views_evidence decides it) instead of 0.
  bool undecided_without_model = false;
};

// Past views of the depth camera (free_space_evidence views, docs/DYNAMIC.md): up to kMax depth
// maps of one pyramid level with the poses they were taken from, the newest last or anywhere (the
// order does not matter).
struct PastViews {
  static constexpr int kMax = 16;
  View2D<const float> depth[kMax];  // metres, 0 = no reading; unmasked (a mover's readings count)
  SE3 view_T_world[kMax];
  Intrinsics K;  // of the stored level
  int count = 0;
};

// One depth quantisation step at depth z (metres).
SEAMLESS_HD inline float depth_step(const DynamicInput& in, float z) {
  return in.K.fx > 0.f ? z * z * in.disparity_step_per_baseline / in.K.fx : 0.f;
}

// The residual threshold at depth z: the larger of residual_min and residual_sigmas * sigma(z) plus
// one quantisation step. A reading lies within half a step of the true surface and so does the
// model (an average of such readings), so the two can be a whole step apart with no noise at all:
// 6.7 cm at 3.25 m at 320x240, more than 3 sigma of the noise model, and a far wall seen one step
// in front of its model made speckles in the mask. The noise comes on top of that step.
SEAMLESS_HD inline float dynamic_threshold(const DynamicInput& in, float z) {
  return fmaxf(in.residual_min, in.residual_sigmas * in.noise_coeff * z * z + depth_step(in, z));
}

// What the volume shows of the space at a measured point: the 8 voxels of its cell (the trilinear
// TSDF's), each observed by at least min_weight frames (weight is frames fused, up to
// volume.max_weight). Seen free: their distance there is at least half the truncation, i.e. earlier
// rays passed through the point to a surface behind it (voxels more than the truncation in front of
// every reading hold exactly +truncation, a static surface's own voxels about 0; half of it splits
// the two). Occupied: observed, and less than that (a surface is there, or the point is inside
// one). Unknown: a voxel missing (the voxel-hashed volume stores only the band of +-truncation
// around surfaces, so most of the space between the camera and a wall is unknown) or not observed
// enough.
enum class SpaceEvidence : std::uint8_t { unknown, seen_free, occupied };

template <class Acc>
SEAMLESS_HD inline SpaceEvidence space_evidence(const Acc& a, vec3 p_world, float min_weight, BlockCache& c) {
  const vec3 q = a.geom.to_voxel(p_world);
  const int3 g0 = floor_to_int(q);
  const Voxel* v[8];
  if (!cell_voxels(a, g0, c, v)) return SpaceEvidence::unknown;
  for (int k = 0; k < 8; ++k)
    if (!(voxel_observed(*v[k]) && voxel_weight(*v[k]) >= min_weight)) return SpaceEvidence::unknown;
  const vec3 f = q - to_vec3(g0);
  float sdf = 0.f;
  for (int k = 0; k < 8; ++k)
    sdf += voxel_sdf(*v[k], a.geom.truncation) * (k & 1 ? f.x : 1.f - f.x) * ((k >> 1) & 1 ? f.y : 1.f - f.y) *
           (k >> 2 ? f.z : 1.f - f.z);
  return sdf >= 0.5f * a.geom.truncation ? SpaceEvidence::seen_free : SpaceEvidence::occupied;
}

// What the past views show of the world point p. Seen through (free) by a view: p lies in front of
// every reading of the 3x3 pixels around its projection there by more than the residual threshold,
// so the ray of each passed through p to a surface behind it. All nine readings must exist and lie
// behind: at a silhouette the window holds the near object's readings too, so a point on a static
// object's edge is never seen through by a neighbouring pixel that saw past the edge (the same 3x3
// rule as free-space carving, kernels/recon/tsdf_fusion.inl). Seen at: the reading at its
// projection lies within the threshold of it (a surface was there). Neither: out of every view,
// or hidden behind nearer readings. A static surface is never seen through: its point is either
// seen at or hidden.
enum class ViewEvidence : std::uint8_t { none, seen_at, seen_through };

SEAMLESS_HD inline ViewEvidence view_evidence(const DynamicInput& in, const PastViews& views, vec3 p_world) {
  ViewEvidence e = ViewEvidence::none;
  for (int k = 0; k < views.count; ++k) {
    const vec3 p = views.view_T_world[k] * p_world;
    if (!(p.z > 0.f)) continue;
    const vec2 uv = views.K.project(p);
    const int u0 = floor_int(uv.x + 0.5f), v0 = floor_int(uv.y + 0.5f);
    const View2D<const float>& d = views.depth[k];
    if (!d.inside(u0 - 1, v0 - 1) || !d.inside(u0 + 1, v0 + 1)) continue;
    const float threshold = dynamic_threshold(in, p.z);
    const float centre = d(u0, v0);
    if (fabsf(centre - p.z) <= threshold) e = ViewEvidence::seen_at;
    if (!(centre > p.z + threshold)) continue;  // the usual case of a static point: decided by one read
    bool through = true;
    for (int dy = -1; dy <= 1 && through; ++dy)
      for (int dx = -1; dx <= 1 && through; ++dx) through = d(u0 + dx, v0 + dy) > p.z + threshold;
    if (through) return ViewEvidence::seen_through;
  }
  return e;
}

template <Executor Exec> struct Dynamic {
  // Candidates (1) per pixel: the measurement lies in front of the model, either (a) no model plane
  // near its projection lies within the residual threshold of it (point-to-plane, either side) and
  // it is in front of one of them by more than the threshold (planes it is behind are occluders'),
  // or (b) by more than free_space from the nearest model surface along the ray. Pixels without
  // depth or without any model surface near their projection are 0 (nothing to compare with:
  // unknown space is not evidence of motion). Only "in front" counts: a measurement behind the
  // model is what an object that left, or background it uncovered, gives, and fusing it carves the
  // old surface away.
  static void classify_dynamic(const Exec& ex, DynamicInput in, View2D<std::uint8_t> candidates);

  // Movers move: a candidate whose surface has stayed in place is static. Each candidate carries
  // an age, the consecutive frames it has been a candidate, and an anchor, the depth (in this
  // frame's camera) of where its surface was when the age began. Its point, taken into the previous
  // frame's camera (prev_T_cur), lands on a pixel there; the oldest candidate within search_radius
  // of it whose anchor, seen from this camera, lies within the residual threshold of the
  // measurement passes on its age (plus one) and anchor; with none, the age starts at 1 at the
  // measured depth (so a surface that creeps along its ray a little each frame starts over once it
  // is a threshold away). The window bridges the pixels that a noisy classification leaves out of
  // a region from one frame to the next (a lone pixel chain would rarely survive 30 frames of
  // them); ages spread from one surface into a neighbouring one at its depth by at most
  // search_radius pixels a frame. A candidate
  // older than static_after frames (0: never) is cleared. That ends two loops the mask would
  // otherwise keep forever, since masked pixels are never fused: a static surface first seen in
  // front of one seen before (a chair's seat after the floor beneath it was seen from the side),
  // and a person who stopped (as in ReFusion, Palazzolo et al. 2019, a mover at rest joins the
  // map). Non-candidates get age 0 and anchor 0.
  // Evidence of free space from past views (free_space_evidence views), after ReFusion (Palazzolo
  // et al. 2019, section III-D: a measurement in front of the model is dynamic only where earlier
  // frames saw empty space), with the last views' depth maps as the record of it instead of free
  // space stored in the volume (no blocks in front of the readings to allocate, fuse and march
  // through). Per pixel, from the model test's candidates (1) and undecided pixels (2: a reading
  // with no model near, DynamicInput::undecided_without_model), by view_evidence of its point:
  // - seen through by a view: a candidate (1), undecided or not;
  // - a model candidate that continues a mover of the previous frame: within search_radius pixels of
  //   where its point lands in the previous frame's camera (prev_T_cur) a pixel that frame kept as
  //   1 (prev_kept, filter_dynamic's) has a depth (prev_depth) within the residual threshold of the
  //   point's: 1. The space a mover covers was last seen empty before it came, perhaps by views
  //   older than the history (the back half of a ball rolling into a region the orbit saw seconds
  //   ago, where in the recent views the ball itself stood);
  // - a model candidate that no view saw at all (out of the views, or hidden): 2, dynamic this frame
  //   but not continued by the next (it needs evidence of its own by then: once the views hold
  //   it, it is seen through, or seen at, i.e. static);
  // - an undecided pixel that continues a mover (as above): 2. Where no model lies near a mover's
  //   edge (the floor its own body hid), the model test cannot call the edge's pixels candidates;
  //   fused, they become model that explains the mover frame after frame as it moves on (a ball's
  //   trailing side). 2, not 1: a static surface a mover reveals is never continued from itself,
  //   so its mask cannot outlive the mover's neighbourhood;
  // - else 0.
  // So a surface first seen in front of one seen before (a chair's seat after the floor beneath
  // it) is masked at most until a view holds it, then fused; a person walking into space the
  // camera saw past is a candidate and stays one while the model test holds. prev_kept may be
  // empty (data == nullptr: no continuation).
  static void views_evidence(const Exec& ex, DynamicInput in, SE3 world_T_cur, PastViews views,
                             View2D<const std::uint8_t> prev_kept, View2D<const float> prev_depth, SE3 prev_T_cur,
                             View2D<std::uint8_t> candidates);

  static void age_dynamic(const Exec& ex, DynamicInput in, View2D<const float> prev_anchor,
                          View2D<const std::uint8_t> prev_age, SE3 prev_T_cur, int static_after,
                          View2D<std::uint8_t> candidates, View2D<std::uint8_t> age, View2D<float> anchor);

  // Region and temporal consistency: a candidate stays dynamic when at least min_support of the
  // (2r+1)^2 candidates around it (itself included) are candidates, or when the previous frame kept
  // it (its `kept`, not its grown mask; prev may be empty: data == nullptr); a kept pixel keeps its
  // candidate's value (views_evidence's 2 marks one not to be continued). Then the kept pixels
  // are dilated by r into neighbours whose depth is within max_step of theirs (the silhouette's
  // mixed pixels, never the background behind) and into neighbours without a reading (the sensor
  // drops a mover's silhouette and scattered pixels on it: a fifth of a person's pixels in the
  // synthetic Kinect model; they carry no depth to fuse or track, but the mask is also what the
  // physics and the view show). The opening removes isolated speckles of noise; the previous frame's
  // kept pixels keep a mover's thin parts (arms) that flicker in and out of the support test.
  static void filter_dynamic(const Exec& ex, View2D<const std::uint8_t> candidates, View2D<const std::uint8_t> prev,
                             View2D<const float> depth, int radius, int min_support, float max_step,
                             View2D<std::uint8_t> kept, View2D<std::uint8_t> mask);

  // Zeroes the vertices and normals of pyramid level pixels whose 2^level x 2^level block of the
  // full-resolution mask holds a dynamic pixel: the trackers then give them weight 0 (a zero vertex
  // is no reading).
  static void mask_vertices(const Exec& ex, View2D<const std::uint8_t> mask, int scale, View2D<vec3> vertices,
                            View2D<vec3> normals);

  // Zeroes the depth of dynamic pixels (fusion then skips them).
  static void mask_depth(const Exec& ex, View2D<const std::uint8_t> mask, View2D<float> depth);

  // Dynamic pixels in a mask (the frame's masked fraction for summary.json).
  static std::int64_t count_dynamic(const Exec& ex, View2D<const std::uint8_t> mask);
};

// The candidate test's positive evidence of free space (ReFusion, Palazzolo et al. 2019, section
// III-D: a measurement in front of the model is dynamic only where earlier frames saw through that
// space), read from the volume through its accessor (HashAccess, DenseAccess; family recon/dynamic).
template <Executor Exec, class Acc> struct DynamicSpace {
  // Clears each candidate whose measured point (the depth at world_T_camera) is not where the volume
  // shows free space (space_evidence): with require_seen_free, every candidate that is not seen
  // free (unknown space too); without, only the occupied ones (the volume holds a static surface
  // there, e.g. a face of an object revealed at a depth edge). Earlier frames' rays that never
  // passed there (a chair's seat first seen from above after the floor beneath it was seen from the
  // side) give no free space, so such a surface is not a candidate and gets fused.
  static void require_free_space(const Exec& ex, Acc a, View2D<const float> depth, Intrinsics K, SE3 world_T_camera,
                                 float min_weight, bool require_seen_free, View2D<std::uint8_t> candidates);
};

}  // namespace seamless::kernels
