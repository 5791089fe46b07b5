// How the dynamic mask agrees with the ground truth of the synthetic room's movers (the mask
// test of docs/DYNAMIC.md): counted per frame by TrackingSession when the frame carries the movers'
// mask, summed up over a run for summary.json (`dynamic.mask`) and the tests.
#pragma once
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "core/math.hpp"
#include "kernels/scene/movers.hpp"

namespace seamless {

// A frame's pixel counts. Mover ids are 1-based (the truth mask's values); index id - 1 below.
struct MaskScore {
  std::int64_t pixels = 0;                              // of the image
  std::int64_t truth = 0;                               // pixels that see a mover
  std::int64_t masked = 0;                              // pixels of the dynamic mask
  std::int64_t both = 0;                                // pixels in both
  std::vector<std::int64_t> mover_truth, mover_masked;  // each mover's pixels, and those of them masked
  // Each mover's distance from the camera (its nearest capsule's surface, metres); +infinity for
  // one not in the room at this frame's time.
  std::vector<float> mover_distance;
  double iou() const;  // both / union; 1 when both are empty
};

// truth: the movers' mask (mover id per pixel, 0 the static room); mask: the dynamic mask (non-zero
// dynamic), of the same size. movers: the frame's capsules in the ground truth's frame, and eye the
// camera's position there (the ground-truth pose).
MaskScore score_mask(const std::vector<std::uint8_t>& truth, const std::vector<std::uint8_t>& mask,
                     const kernels::movers::Scene& movers, vec3 eye);

// The condition for a frame to enter the IoU statistics: a person in the room, every person
// at least kMinMoverDistance from the camera (nearer, one fills the view and much of them lies
// nearer than the sensor's minimum depth), and the movers on at least kMinTruthFraction of the
// image (a sliver at the border has a handful of pixels, where one pixel of silhouette is already a
// tenth of the IoU). people: the persons' mover ids; empty: every mover counts as one.
constexpr float kMinMoverDistance = 0.5f;  // metres
constexpr double kMinTruthFraction = 0.01;
bool mask_scored(const MaskScore& s, const std::vector<int>& people);

// A run's mask quality: IoU over the scored frames; recall per mover and precision over every frame
// with a score (a mover near the camera, at the border or alone in the room is still one to find).
struct MaskQuality {
  int frames = 0;                                      // scored frames
  double min_iou = 0, mean_iou = 0;                    // NaN when no frame was scored
  std::vector<std::pair<std::int64_t, double>> below;  // scored frames with IoU under kGoodIou: (frame, IoU)
  std::vector<double> mover_recall;                    // index id - 1; NaN for a mover never seen
  double precision = 0;                                // masked pixels that see a mover; NaN when nothing was masked
};
constexpr double kGoodIou = 0.8;  // the mask test's bound on every scored frame

// frame_scores: (frame index, its score) of every frame that has one. Nothing when none has.
std::optional<MaskQuality> mask_quality(const std::vector<std::pair<std::int64_t, MaskScore>>& frame_scores,
                                        const std::vector<int>& people);

}  // namespace seamless
