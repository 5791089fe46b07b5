// Dynamic section (`dynamic:`): people and moving objects kept out of tracking and fusion, and
// free-space carving of what they left behind (docs/DYNAMIC.md). Off by default: then
// every run is bit for bit what it was without this section.
#pragma once
#include "core/params.hpp"

namespace seamless {

// What a candidate must show of the volume at its measured point (docs/DYNAMIC.md, "Evidence of free
// space"): nothing more (none), not a surface the volume holds (not_occupied), or space that
// earlier frames saw through (seen_free, ReFusion's free-space test), or space one of the last few
// views saw through (views: their depth maps kept, nothing stored in the volume).
enum class FreeSpaceEvidence { none, not_occupied, seen_free, views };
inline std::span<const EnumName<FreeSpaceEvidence>> enum_names(FreeSpaceEvidence) {
  static constexpr EnumName<FreeSpaceEvidence> names[] = {{FreeSpaceEvidence::none, "none"},
                                                          {FreeSpaceEvidence::not_occupied, "not_occupied"},
                                                          {FreeSpaceEvidence::seen_free, "seen_free"},
                                                          {FreeSpaceEvidence::views, "views"}};
  return names;
}

struct DynamicParams {
  bool enabled = false;
  // Residual threshold: max(residual_min, residual_sigmas * noise_coeff * z^2 + one depth
  // quantisation step z^2 / (8 fx b), kernels/recon/dynamic.hpp). Kinect v1 depth
  // noise grows with the square of the distance (Khoshelham & Elberink 2012: about 1.5 mm at 1 m,
  // 4 cm at 5 m, so sigma ~ 1.5e-3 z^2); 3 sigma keeps 99.7% of static noise out. The floor of
  // 3 cm covers what the noise model does not: the pose error of the prediction and the raycast's
  // trilinear surface (a voxel or two at the default sizes).
  float residual_min = 0.03f;
  float noise_coeff = 0.0015f;
  float residual_sigmas = 3.f;
  // Free-space violation: a measurement more than this many volume.truncation widths in front of
  // the nearest model surface along its ray sees through space the model says is empty.
  float free_space_truncations = 3.f;
  int search_radius = 2;          // pixels: projective association is a pixel or two off at depth edges
  int support_radius = 1;         // pixels: the consistency window is (2r+1)^2
  int min_support = 5;            // of the window's 9 pixels (r = 1): a majority
  float dilate_max_step = 0.05f;  // metres: the dilation never crosses a larger depth step
  // Free-space carving: a voxel more than this many truncation widths in front of the measured depth
  // (and of its 3x3 neighbours) is reset to free; 0: only the running average (KinectFusion).
  float carve_truncations = 3.f;
  // Movers move: a candidate pixel whose surface has stayed in place (the same point, within the
  // residual threshold) for more than this many consecutive frames is static and becomes part of
  // the map: a surface first seen in front of one seen before, or a person who stopped. 0: never
  // (the default). Off by default because it is a trade-off not yet resolved: on the demo's scene
  // 30 (1 s) ends the loop that keeps a newly seen chair seat masked (worst-frame IoU 0.30 -> 0.61)
  // but the live demo then leaves 203 ghost vertices of the person instead of 5 (docs/DYNAMIC.md).
  int static_after_frames = 0;
  // Evidence of free space at the measured point (docs/DYNAMIC.md, "Evidence of free space" and
  // "Evidence from past views"). views (the default) keeps the last few depth maps and asks that one
  // of them saw through the point (or that it continues a mover of the previous frame): it ends the
  // newly-seen-surface loop (a chair's seat first seen from above after the floor beneath it, which
  // stayed masked to the end of the run) for a few depth-map copies a frame; on the test scene the
  // worst frame's IoU goes 0.30 -> 0.82 at 320x240. seen_free asks the volume instead, which the
  // voxel-hashed volume (the default layout) then has to store in front of the readings
  // (Volume::set_free_space_storage: several times the blocks, fused every frame); none is the
  // model test alone.
  FreeSpaceEvidence free_space_evidence = FreeSpaceEvidence::views;
  // Frames a voxel must have been fused to count as observed. 1: free-space carving resets a voxel
  // it carves to weight 1 every frame it carves it (kernels/recon/tsdf_fusion.inl), so space more
  // than carve_truncations in front of every reading never holds more, and that is most of the
  // space a person walks through; the carve already asks the 3x3 readings around the pixel to
  // agree, which keeps one mixed pixel at a silhouette from making free space. (With 2 the dense
  // grid's seen_free lost a quarter of the person's IoU: docs/DYNAMIC.md.)
  float evidence_min_weight = 1.f;
  // free_space_evidence views: the depth maps of the last evidence_views frames taken every
  // evidence_view_interval frames, at pyramid level evidence_view_level (kernels::PastViews). 16
  // every 5 frames reach back 2.7 s at 30 fps: a person walking at 0.8 m/s has left space that one
  // of them saw empty (their own width is 0.4 s away), one who stands still longer is fused. The
  // interval bounds how long a static surface the camera newly reveals in front of the model stays
  // masked (no view has evidence of it until the next one is kept): 0.17 s; with 10, the test
  // scene's chair back at 640x480 took three of its frames under IoU 0.8 (docs/DYNAMIC.md).
  int evidence_views = 16;
  int evidence_view_interval = 5;
  int evidence_view_level = 1;
  bool write_masks = false;  // dynamic_mask/<frame>.png (255 = dynamic) into the run's folder

  template <class V> void visit(V& v) {
    v("enabled", enabled,
      "find dynamic pixels (people, moving objects) from the depth and the model, keep them out of tracking and "
      "fusion, and carve free space (docs/DYNAMIC.md); false: exactly the static pipeline");
    v("residual_min", residual_min,
      "smallest point-to-plane residual in front of the model that marks a pixel dynamic, metres", Range{0.0, 1.0});
    v("noise_coeff", noise_coeff,
      "depth noise model sigma(z) = noise_coeff * z^2 (Khoshelham & Elberink 2012), 1/metres", Range{0.0, 1.0});
    v("residual_sigmas", residual_sigmas, "residual threshold in depth-noise sigmas at the pixel's depth",
      Range{0.0, 100.0});
    v("free_space_truncations", free_space_truncations,
      "a measurement this many volume.truncation widths in front of the nearest model surface along its ray is "
      "dynamic (free-space violation)",
      Range{0.5, 100.0});
    v("search_radius", search_radius, "pixels around a measurement's projection searched for the model surface",
      Range{0, 8});
    v("support_radius", support_radius, "radius of the consistency window, pixels", Range{1, 8});
    v("min_support", min_support,
      "candidates needed in the (2r+1)^2 consistency window for a pixel to stay dynamic (without the previous "
      "frame's mask having it)",
      Range{1, 289});
    v("dilate_max_step", dilate_max_step,
      "the mask grows by support_radius into neighbours whose depth differs by at most this, metres", Range{0.0, 10.0});
    v("carve_truncations", carve_truncations,
      "free-space carving: voxels this many truncation widths in front of the measurement are reset to free "
      "space; 0: off",
      Range{0.0, 100.0});
    v("static_after_frames", static_after_frames,
      "a dynamic pixel whose surface has stayed in place for more than this many consecutive frames is static "
      "(a person who stopped, a surface first seen in front of one seen before); 0: never (docs/DYNAMIC.md: a "
      "trade-off, off by default)",
      Range{0, 250});
    v("free_space_evidence", free_space_evidence,
      "what a dynamic candidate must show at its measured point: none, not_occupied (no surface the volume holds "
      "there), seen_free (space earlier frames saw through; ReFusion's free-space test; the voxel-hashed volume "
      "then also stores the free space in front of the readings: more blocks, docs/DYNAMIC.md) or views (space "
      "one of the last evidence_views depth maps saw through; also decides pixels with no model near)");
    v("evidence_min_weight", evidence_min_weight,
      "frames a voxel must have been fused for free_space_evidence to count it as observed", Range{0.0, 1000.0});
    v("evidence_views", evidence_views, "free_space_evidence views: past depth maps kept", Range{1, 16});
    v("evidence_view_interval", evidence_view_interval, "free_space_evidence views: frames between two kept depth maps",
      Range{1, 1000});
    v("evidence_view_level", evidence_view_level,
      "free_space_evidence views: pyramid level of the kept depth maps (0: full resolution; the coarsest level when "
      "larger)",
      Range{0, 8});
    v("write_masks", write_masks, "write each frame's mask as dynamic_mask/<frame>.png (255 = dynamic)");
  }
};

}  // namespace seamless
