#include "recon/mask_score.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.hpp"

namespace seamless {

double MaskScore::iou() const {
  const std::int64_t uni = truth + masked - both;
  return uni > 0 ? static_cast<double>(both) / static_cast<double>(uni) : 1.0;
}

MaskScore score_mask(const std::vector<std::uint8_t>& truth, const std::vector<std::uint8_t>& mask,
                     const kernels::movers::Scene& movers, vec3 eye) {
  if (truth.size() != mask.size())
    throw Error("score_mask: the movers' mask has " + std::to_string(truth.size()) + " pixels, the dynamic mask " +
                std::to_string(mask.size()));
  MaskScore s;
  s.pixels = static_cast<std::int64_t>(truth.size());
  auto grow = [&s](std::size_t ids) {
    if (ids <= s.mover_truth.size()) return;
    s.mover_truth.resize(ids, 0), s.mover_masked.resize(ids, 0);
    s.mover_distance.resize(ids, std::numeric_limits<float>::infinity());
  };
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const int id = truth[i];
    const bool m = mask[i] != 0;
    s.masked += m;
    if (id == 0) continue;
    grow(static_cast<std::size_t>(id));
    ++s.truth, ++s.mover_truth[id - 1];
    if (m) ++s.both, ++s.mover_masked[id - 1];
  }
  for (int k = 0; k < movers.count; ++k) {
    const kernels::movers::Capsule& c = movers.c[k];
    if (c.mover < 1) continue;
    grow(static_cast<std::size_t>(c.mover));
    kernels::movers::Scene one;
    one.count = 1, one.c[0] = c;
    float& d = s.mover_distance[c.mover - 1];
    d = std::min(d, kernels::movers::distance(one, eye));
  }
  return s;
}

bool mask_scored(const MaskScore& s, const std::vector<int>& people) {
  bool present = false;
  for (std::size_t k = 0; k < s.mover_distance.size(); ++k) {
    const int id = static_cast<int>(k) + 1;
    if (!people.empty() && std::find(people.begin(), people.end(), id) == people.end()) continue;
    if (!std::isfinite(s.mover_distance[k])) continue;  // not in the room now
    if (s.mover_distance[k] < kMinMoverDistance) return false;
    present = true;
  }
  return present && static_cast<double>(s.truth) >= kMinTruthFraction * static_cast<double>(s.pixels);
}

std::optional<MaskQuality> mask_quality(const std::vector<std::pair<std::int64_t, MaskScore>>& frame_scores,
                                        const std::vector<int>& people) {
  if (frame_scores.empty()) return std::nullopt;
  MaskQuality q;
  q.min_iou = 1;
  double iou_sum = 0;
  std::int64_t masked = 0, both = 0;
  std::vector<std::int64_t> truth_n, hit_n;
  for (const auto& [frame, s] : frame_scores) {
    masked += s.masked, both += s.both;
    if (s.mover_truth.size() > truth_n.size())
      truth_n.resize(s.mover_truth.size(), 0), hit_n.resize(s.mover_truth.size(), 0);
    for (std::size_t k = 0; k < s.mover_truth.size(); ++k)
      truth_n[k] += s.mover_truth[k], hit_n[k] += s.mover_masked[k];
    if (!mask_scored(s, people)) continue;
    const double iou = s.iou();
    ++q.frames;
    iou_sum += iou;
    q.min_iou = std::min(q.min_iou, iou);
    if (iou < kGoodIou) q.below.push_back({frame, iou});
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  q.mean_iou = q.frames ? iou_sum / q.frames : nan;
  if (q.frames == 0) q.min_iou = nan;
  for (std::size_t k = 0; k < truth_n.size(); ++k)
    q.mover_recall.push_back(truth_n[k] ? static_cast<double>(hit_n[k]) / static_cast<double>(truth_n[k]) : nan);
  q.precision = masked ? static_cast<double>(both) / static_cast<double>(masked) : nan;
  return q;
}

}  // namespace seamless
