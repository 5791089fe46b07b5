// Is input.depth_scale right? Two checks of a depth image against what a depth camera can report.
//
// 1. Range: the median depth must lie in 0.2-10 m (where every indoor RGB-D camera measures).
// 2. Quantisation (sensor physics): a Kinect v1 (and every PrimeSense-type structured-light camera)
//    measures disparity d = f b / z in 1/8-pixel steps, so the depths it can report are discrete,
//    with a step that grows with the square of the depth:  dz = z^2 / (8 f b)  (Khoshelham &
//    Elberink 2012; baseline b = 0.075 m, 1/8-pixel disparity steps: Konolige & Mihelich, "Technical
//    description of Kinect calibration", ROS wiki kinect_calibration/technical; IR focal length
//    f = 580 px, with which TUM's real depth gives back its 5000 to 1%: tests/io). In the 16-bit
//    PNG a step between neighbouring distinct raw values g at raw value R is therefore
//        g = (R / s)^2 / (8 f b) * s  =  R^2 / (8 f b s),   so   s = R^2 / (8 f b g),
//    whatever the scene: the steps themselves say how many units make a metre. A wrong scale that
//    still gives a plausible median (TUM's 5000 read as millimetres: everything 5x too far, median
//    ~6 m) shows as steps 5x too fine for the depth they claim to be at.
//    The estimate is informative only where the steps are resolved, i.e. larger than the PNG's unit
//    (a ToF camera, a filtered or interpolated depth map, or a Kinect at close range stored in
//    millimetres fill every integer: then nothing can be said and nothing is reported).
#pragma once
#include <cstdint>
#include <string>

#include "core/buffer.hpp"

namespace seamless {

// What the raw values of one depth image say about their scale.
struct DepthQuantisation {
  bool informative = false;             // enough resolved steps (median gap >= kMinGap units, >= kMinSteps gaps)
  double kinect_scale = 0;              // units per metre at which the steps are a Kinect v1's (median over steps)
  std::int64_t steps = 0;               // gaps between neighbouring distinct values used
  double median_gap = 0;                // in raw units
  std::uint16_t lo = 0, hi = 0;         // raw values spanned (10th to 95th percentile of the valid pixels)
  static constexpr int kMinGap = 3;     // a gap of 1-2 units is the PNG's rounding as much as the sensor's step
  static constexpr int kMinSteps = 30;  // a median over fewer steps is noise
};

// raw: a depth PNG's values; 0 and 65535 (7-Scenes) are "no reading".
DepthQuantisation depth_quantisation(const Image<std::uint16_t>& raw);

struct DepthScaleVerdict {
  enum Kind { consistent, not_measurable, doubtful, wrong } kind = not_measurable;
  double likely_scale = 0;  // wrong / doubtful: what the steps suggest (a common scale when one is near)
  std::string message;      // wrong / doubtful: the explanation for the user (names input.depth_scale)
};

// Compares `scale` (units per metre) with q. The verdict is
//  - wrong (a config error) when the steps disagree by a factor of 2.5 or more AND point, within 15%,
//    at one of the scales depth files are written with (1000: millimetres; 5000: TUM): two
//    independent coincidences (a Kinect's step geometry and a file convention) leave no doubt;
//  - doubtful (a warning) when they disagree by more than a factor of 2 otherwise: possibly a
//    camera of another geometry (a RealSense D400 stereo camera's steps are about 3x finer);
//  - consistent within a factor of 2, not_measurable when q is not informative.
DepthScaleVerdict judge_depth_scale(const DepthQuantisation& q, double scale, const std::string& file);

// What a source does with its first frames: judges each until one is informative (at most
// kMaxFrames, a close-up start may not be), then stops. wrong: throws an Error (it names
// input.depth_scale: a setting, not a bad frame); doubtful: one warning; consistent: one info line.
// Disabled (input.check_depth_scale: false): does nothing.
class DepthScaleCheck {
 public:
  static constexpr int kMaxFrames = 10;
  DepthScaleCheck(double scale, bool enabled) : scale_(scale), done_(!enabled) {}
  void check(const Image<std::uint16_t>& raw, const std::string& file);

 private:
  double scale_;
  bool done_;
  int frames_ = 0;
};

// One-pixel gaps of forward-registered depth (kernels/io/fill_gaps.hpp), on the host: input decoding.
// in and out are host images of one size, out not in.
void fill_depth_gaps_host(const Image<float>& in, Image<float>& out);
// The fraction of all pixels that fill_depth_gaps_host would fill. Above kGapHint a source says once
// that input.fill_gaps would help (normals and fusion fail at such pixels: the real frames_box_50
// sample has 27% of its pixels in such gaps, and ICP loses every frame without filling them).
double fillable_gap_fraction(const Image<float>& depth);
inline constexpr double kGapHint = 0.05;
// One warning naming `file` when depth has more than kGapHint of fillable gaps (a source's first frame).
void hint_depth_gaps(const Image<float>& depth, const std::string& file);

// Median of the valid depths (metres; every 7th pixel); 0 when none.
float median_depth(const Image<float>& depth);
// Throws an Error naming `file`, the median and input.depth_scale when the median depth lies outside
// 0.2-10 m; the message suggests a scale that would put it at 2 m.
void check_median_depth(const Image<float>& depth, double scale, const std::string& file);

}  // namespace seamless
