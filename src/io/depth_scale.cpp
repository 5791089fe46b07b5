#include "io/depth_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/log.hpp"
#include "kernels/io/fill_gaps.hpp"

namespace seamless {
namespace {

// Kinect v1 triangulation (depth_scale.hpp): one disparity step is dz = z^2 * kStepPerZ2.
constexpr double kBaseline = 0.075;                                     // metres, IR projector to IR camera
constexpr double kFocalIr = 580.0;                                      // pixels, IR camera at 640x480
constexpr double kDisparityStep = 0.125;                                // pixels
constexpr double kStepPerZ2 = kDisparityStep / (kFocalIr * kBaseline);  // 1/m

std::string fmt(double v, int decimals = 0) {
  char b[64];
  std::snprintf(b, sizeof b, "%.*f", decimals, v);
  return b;
}

}  // namespace

DepthQuantisation depth_quantisation(const Image<std::uint16_t>& raw) {
  DepthQuantisation q;
  // A histogram of the raw values: their distinct values and percentiles in one pass.
  std::vector<std::uint32_t> count(65536, 0);
  const std::uint16_t* d = raw.buffer().data();
  std::int64_t valid = 0;
  for (std::int64_t i = 0; i < raw.buffer().size(); ++i)
    if (d[i] != 0 && d[i] != 65535) ++count[d[i]], ++valid;
  if (valid < 100) return q;
  // Between the 10th and 95th percentile: the tails hold isolated outliers (flying pixels, edges)
  // whose gaps are gaps in the scene, not in the sensor's steps.
  const std::int64_t lo_rank = valid / 10, hi_rank = valid * 95 / 100;
  std::int64_t seen = 0;
  int lo = -1, hi = -1;
  for (int v = 1; v < 65535 && hi < 0; ++v) {
    seen += count[v];
    if (lo < 0 && seen > lo_rank) lo = v;
    if (seen > hi_rank) hi = v;
  }
  q.lo = static_cast<std::uint16_t>(lo);
  q.hi = static_cast<std::uint16_t>(hi);
  // Each gap g between neighbouring distinct values around R says s = k R^2 / g; gaps in the scene
  // (no surface at some depth) give too small an s, but they are few: the median ignores them.
  std::vector<double> scales, gaps;
  int prev = -1;
  for (int v = lo; v <= hi; ++v) {
    if (count[v] == 0) continue;
    if (prev >= 0) {
      const double g = v - prev, R = 0.5 * (v + prev);
      gaps.push_back(g);
      scales.push_back(kStepPerZ2 * R * R / g);
    }
    prev = v;
  }
  q.steps = static_cast<std::int64_t>(gaps.size());
  if (q.steps == 0) return q;
  auto median = [](std::vector<double>& v) {
    std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
    return v[v.size() / 2];
  };
  q.median_gap = median(gaps);
  q.kinect_scale = median(scales);
  q.informative = q.steps >= DepthQuantisation::kMinSteps && q.median_gap >= DepthQuantisation::kMinGap;
  return q;
}

DepthScaleVerdict judge_depth_scale(const DepthQuantisation& q, double scale, const std::string& file) {
  DepthScaleVerdict v;
  if (!q.informative) return v;  // not_measurable
  const double ratio = q.kinect_scale / scale;
  if (ratio <= 2.0 && ratio >= 0.5) {
    v.kind = DepthScaleVerdict::consistent;
    return v;
  }
  struct Convention {
    double scale;
    const char* name;
  };
  const Convention conventions[] = {{1000.0, "millimetres: frame folders, Kinect/OpenNI"}, {5000.0, "TUM RGB-D"}};
  const Convention* near = nullptr;
  for (const Convention& c : conventions)
    if (std::fabs(q.kinect_scale / c.scale - 1.0) <= 0.15) near = &c;
  const bool wrong = near && (ratio >= 2.5 || ratio <= 0.4);
  v.kind = wrong ? DepthScaleVerdict::wrong : DepthScaleVerdict::doubtful;
  v.likely_scale = near ? near->scale : std::round(q.kinect_scale);
  std::string steps = "the " + std::to_string(q.steps) + " steps between neighbouring depth values of '" + file +
                      "' from " + fmt(q.lo / scale, 2) + " to " + fmt(q.hi / scale, 2) +
                      " m (at that scale; median step " + fmt(q.median_gap) +
                      " units) are a Kinect v1's disparity steps (dz = z^2 / (8 f b), b 7.5 cm, " + "f 580 px) at " +
                      fmt(q.kinect_scale) + " units per metre";
  if (wrong) {
    v.message = "input.depth_scale " + fmt(scale) + " contradicts the depth images: " + steps + ", " + fmt(ratio, 2) +
                "x the configured scale and close to " + fmt(near->scale) + " (" + near->name +
                "): set input.depth_scale: " + fmt(near->scale) +
                " (or input.check_depth_scale: false for a camera that is not a Kinect v1-type structured-light "
                "sensor)";
  } else {
    v.message = "input.depth_scale " + fmt(scale) + " may be wrong: " + steps + " (" + fmt(ratio, 2) +
                "x the configured scale); right for a Kinect v1 / PrimeSense camera would be about " +
                fmt(v.likely_scale) + ", other cameras quantise differently";
  }
  return v;
}

void DepthScaleCheck::check(const Image<std::uint16_t>& raw, const std::string& file) {
  if (done_) return;
  ++frames_;
  const DepthQuantisation q = depth_quantisation(raw);
  const DepthScaleVerdict v = judge_depth_scale(q, scale_, file);
  switch (v.kind) {
    case DepthScaleVerdict::wrong: throw ConfigError(v.message);
    case DepthScaleVerdict::doubtful: spdlog::warn("{}", v.message); break;
    case DepthScaleVerdict::consistent:
      spdlog::info(
          "input.depth_scale {} agrees with the Kinect v1 quantisation steps of '{}' ({} steps suggest {:.0f})", scale_,
          file, q.steps, q.kinect_scale);
      break;
    case DepthScaleVerdict::not_measurable:
      if (frames_ < kMaxFrames) return;
      spdlog::info(
          "input.depth_scale {} could not be checked against quantisation steps: the first {} depth images "
          "show none (median step {:.0f} unit(s): a camera of finer steps, or filtered depth); the median "
          "depth is checked on every frame",
          scale_, frames_, q.median_gap);
      break;
  }
  done_ = true;
}

void fill_depth_gaps_host(const Image<float>& in, Image<float>& out) {
  with_exec(Device::CPU, [&]<class E>(const E& ex) {
    kernels::FillGaps<E>::fill_depth_gaps(ex, in.cview(), out.view(), kernels::kFillGapsMaxRelDiff);
  });
}

double fillable_gap_fraction(const Image<float>& depth) {
  if (depth.buffer().size() == 0) return 0.0;
  Image<float> filled(depth.width(), depth.height(), Device::CPU);
  fill_depth_gaps_host(depth, filled);
  std::int64_t n = 0;
  const float *a = depth.buffer().data(), *b = filled.buffer().data();
  for (std::int64_t i = 0; i < depth.buffer().size(); ++i) n += a[i] <= 0.f && b[i] > 0.f;
  return static_cast<double>(n) / static_cast<double>(depth.buffer().size());
}

void hint_depth_gaps(const Image<float>& depth, const std::string& file) {
  const double f = fillable_gap_fraction(depth);
  if (f > kGapHint)
    spdlog::warn(
        "depth image '{}': {:.0f}% of the pixels are one-pixel gaps between two agreeing depths (depth "
        "registered to colour by forward projection); normals and fusion fail there, ICP may lose track: "
        "set input.fill_gaps: true",
        file, 100 * f);
}

float median_depth(const Image<float>& depth) {
  std::vector<float> v;
  const float* d = depth.buffer().data();
  for (std::int64_t i = 0; i < depth.buffer().size(); i += 7)
    if (d[i] > 0.f) v.push_back(d[i]);
  if (v.empty()) return 0.f;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

void check_median_depth(const Image<float>& depth, double scale, const std::string& file) {
  const float med = median_depth(depth);
  if (med > 0.f && (med < 0.2f || med > 10.f))
    throw InputError("depth image '" + file + "': median depth " + std::to_string(med) + " m with input.depth_scale " +
                     std::to_string(scale) + " is implausible for a depth camera (0.2-10 m); TUM uses 5000, " +
                     "millimetre depth (frame folders) 1000 (a scale of about " + std::to_string(scale * med / 2.0) +
                     " would put the median at 2 m)");
}

}  // namespace seamless
