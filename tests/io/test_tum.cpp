// The TUM reader on real data: /work/shared/data (TUM RGB-D benchmark, Sturm et al. 2012).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "core/buffer.hpp"
#include "core/device.hpp"

#include "io/colour_region.hpp"
#include "io/input_params.hpp"
#include "io/tum_source.hpp"

using namespace seamless;

namespace {

std::string data_dir(const std::string& name) { return std::string(SEAMLESS_TEST_DATA) + "/" + name; }

#define REQUIRE_DATA(dir) \
  if (!std::filesystem::is_directory(dir)) GTEST_SKIP() << "test data folder " << dir << " is absent"

InputParams tum_params(const std::string& dir) {
  InputParams p;
  p.source = InputSource::tum;
  p.path = dir;
  return p;
}

}  // namespace

TEST(TumReader, Rpy150PairsTimestampsAndDepth) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  TumSource src(tum_params(dir));
  ASSERT_EQ(src.size(), 150);
  // The intrinsics preset comes from the folder name (freiburg1); undistorted on input.
  Intrinsics K = src.intrinsics();
  EXPECT_FLOAT_EQ(K.fx, 517.3f);
  EXPECT_FLOAT_EQ(K.cy, 255.3f);
  EXPECT_EQ(K.dist[0], 0.f);
  RgbdFrame f;
  std::vector<double> stamps;
  int frames = 0;
  while (src.next(f)) {
    stamps.push_back(f.timestamp);
    if (frames++ % 30 != 0) continue;  // decode a few fully; all are loaded
    ASSERT_EQ(f.depth.width(), 640);
    ASSERT_EQ(f.rgb.height(), 480);
    std::vector<float> d = f.depth.to_host();
    std::vector<float> valid;
    for (float v : d)
      if (v > 0) valid.push_back(v);
    // A Kinect v1 over a desk: most pixels valid, all within the sensor's reach (0.4 m .. ~8 m;
    // TUM stores depth at 1/5000 m), median around the desk distance.
    EXPECT_GT(valid.size(), d.size() / 2);
    auto [lo, hi] = std::minmax_element(valid.begin(), valid.end());
    EXPECT_GT(*lo, 0.3f);
    EXPECT_LT(*hi, 9.0f);
    std::nth_element(valid.begin(), valid.begin() + valid.size() / 2, valid.end());
    EXPECT_GT(valid[valid.size() / 2], 0.5f);
    EXPECT_LT(valid[valid.size() / 2], 3.0f);
  }
  EXPECT_EQ(frames, 150);
  EXPECT_DOUBLE_EQ(stamps.front(), 1305031229.528748);  // first line of associations.txt
  EXPECT_TRUE(std::is_sorted(stamps.begin(), stamps.end()));
  // 30 Hz camera: 149 intervals of about 1/30 s.
  EXPECT_NEAR((stamps.back() - stamps.front()) / 149, 1.0 / 30, 0.005);
}

TEST(TumReader, AssociationReproducesAssociateDotPy) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  // associations.txt in this folder was made by TUM's associate.py: our pairing must match it.
  auto pairs = associate(read_tum_list(dir + "/rgb.txt"), read_tum_list(dir + "/depth.txt"));
  InputParams p = tum_params(dir);
  p.association = Association::file;
  TumSource src(p);
  const auto& want = src.pairs();
  ASSERT_EQ(pairs.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(pairs[i].rgb.file, want[i].rgb.file);
    EXPECT_EQ(pairs[i].depth.file, want[i].depth.file);
  }
}

TEST(TumReader, GroundTruthInterpolatedAtFrameTimes) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  Trajectory gt = read_tum_trajectory(dir + "/groundtruth.txt");
  TumSource src(tum_params(dir));
  int with_gt = 0;
  for (std::size_t i = 0; i < src.pairs().size(); ++i) {
    RgbdFrame f = src.metadata(i);
    if (!f.ground_truth) continue;
    ++with_gt;
    // The interpolated position lies on the segment between the bracketing mocap samples (100 Hz,
    // so they are < 0.1 s apart); distance to the segment is float rounding only.
    auto it =
        std::lower_bound(gt.begin(), gt.end(), f.timestamp, [](const TumPose& p, double t) { return p.timestamp < t; });
    ASSERT_NE(it, gt.begin());
    const TumPose &a = *(it - 1), &b = *it;
    double s = (f.timestamp - a.timestamp) / (b.timestamp - a.timestamp);
    for (int k = 0; k < 3; ++k) {
      double expect = a.t[k] + s * (b.t[k] - a.t[k]);
      EXPECT_NEAR(f.ground_truth->t.x * (k == 0) + f.ground_truth->t.y * (k == 1) + f.ground_truth->t.z * (k == 2),
                  expect, 1e-6 * std::max(1.0, std::fabs(expect)));
    }
    // Rotation: the angle to each bracketing sample is at most the angle between them (slerp).
    SE3 A = a.se3(), B = b.se3();
    auto angle = [](const SE3& X, const SE3& Y) {
      mat3 D = transpose(X.R) * Y.R;
      double c = (D.m[0][0] + D.m[1][1] + D.m[2][2] - 1) / 2;
      return std::acos(std::clamp(c, -1.0, 1.0));
    };
    double ab = angle(A, B);
    EXPECT_LE(angle(A, *f.ground_truth), ab + 2e-3);  // 2e-3 rad: acos of float rotations near 0
    EXPECT_LE(angle(*f.ground_truth, B), ab + 2e-3);
  }
  // The trimmed ground truth covers the whole chunk (its gaps are later in the sequence).
  EXPECT_EQ(with_gt, 150);
}

TEST(TumReader, AccelerometerPointsUpInTheCameraFrame) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  TumSource src(tum_params(dir));
  std::vector<double> errors;
  for (std::size_t i = 0; i < src.pairs().size(); ++i) {
    RgbdFrame f = src.metadata(i);
    ASSERT_TRUE(f.accelerometer);
    ASSERT_TRUE(f.ground_truth);
    vec3 a = *f.accelerometer;
    // At rest an accelerometer reads the reaction to gravity: world up (+z in the TUM mocap frame)
    // expressed in the camera frame, R^T (0, 0, g).
    vec3 up = transpose(f.ground_truth->R) * vec3{0, 0, 1};
    double c = dot(a, up) / length(a);
    errors.push_back(std::acos(std::clamp(c, -1.0, 1.0)) * 180 / M_PI);
    EXPECT_NEAR(length(a), 9.81, 3.0);  // hand-held: accelerations of a few m/s^2 on top of g
  }
  // Hand motion adds ~1-2 m/s^2 to g (atan(2/9.81) = 11.5 deg); the mocap-to-camera calibration and
  // the ~30 ms accelerometer latency add a few degrees. The median must be well inside that.
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 12.0);
}

TEST(TumReader, NineFrameDeskPairsAllNineByTime) {
  std::string dir = data_dir("tum_fr1_desk_9frames");
  REQUIRE_DATA(dir);
  // This folder's associate.txt lists only the first 2 of its 9 pairs; rgb.txt and depth.txt list
  // all 9 (each depth 10-15 ms after its rgb). TUM's convention (input.association: auto) pairs
  // the lists by time and uses all 9.
  TumSource src(tum_params(dir));
  ASSERT_EQ(src.size(), 9);
  std::int64_t n = 0;
  RgbdFrame f;
  while (src.next(f)) {
    if (n == 0) {
      EXPECT_DOUBLE_EQ(f.timestamp, 1305031453.359684);
    }
    EXPECT_TRUE(f.ground_truth);
    EXPECT_FALSE(f.accelerometer);  // no accelerometer.txt in this folder
    EXPECT_EQ(f.depth.width(), 640);
    ++n;
  }
  EXPECT_EQ(n, 9);
  EXPECT_DOUBLE_EQ(f.timestamp, 1305031453.627706);  // the last line of rgb.txt
  // The file, when asked for, gives its 2 pairs, which agree with pairing by time.
  InputParams p = tum_params(dir);
  p.association = Association::file;
  TumSource file_src(p);
  ASSERT_EQ(file_src.size(), 2);
  EXPECT_EQ(file_src.pairs()[1].depth.file, src.pairs()[1].depth.file);
}

TEST(TumReader, FirstAndMaxFrames) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  InputParams p = tum_params(dir);
  p.first_frame = 10;
  p.max_frames = 5;
  TumSource src(p);
  EXPECT_EQ(src.size(), 5);
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.index, 0);
  EXPECT_DOUBLE_EQ(f.timestamp, src.pairs()[0].rgb.timestamp);
}

// Frames for a GPU pipeline are decoded into page-locked memory that the source keeps from frame
// to frame (one allocation, then asynchronous uploads). That must not change a single pixel, with
// and without undistortion (the two decoding paths), and the memory must really be reused.
TEST(TumReader, PinnedFramesEqualOrdinaryOnesAndKeepTheirMemory) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  for (bool undistort : {true, false}) {
    InputParams p = tum_params(dir);
    p.undistort = undistort;
    p.max_frames = 3;
    TumSource plain(p), pinned(p, /*pinned=*/true);
    RgbdFrame a, b;
    const float* depth_memory = nullptr;
    const uchar3* rgb_memory = nullptr;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(plain.next(a));
      ASSERT_TRUE(pinned.next(b));
      ASSERT_EQ(a.depth.width(), b.depth.width());
      ASSERT_EQ(a.rgb.buffer().bytes(), b.rgb.buffer().bytes());
      EXPECT_EQ(0, std::memcmp(a.depth.buffer().data(), b.depth.buffer().data(), a.depth.buffer().bytes()));
      EXPECT_EQ(0, std::memcmp(a.rgb.buffer().data(), b.rgb.buffer().data(), a.rgb.buffer().bytes()));
      if (k > 0) {
        EXPECT_EQ(b.depth.buffer().data(), depth_memory) << "frame " << k << " reallocated its depth image";
        EXPECT_EQ(b.rgb.buffer().data(), rgb_memory) << "frame " << k << " reallocated its colour image";
      }
      depth_memory = b.depth.buffer().data();
      rgb_memory = b.rgb.buffer().data();
      if (cuda_available()) {
        EXPECT_TRUE(memory::is_pinned(depth_memory));
      }
    }
  }
}

// The largest rectangle of the mask's aspect inside a disc of radius R: its diagonal is the
// diameter, so a 4:3 rectangle is 1.6 R x 1.2 R (to the pixel grid: within 2 pixels, and no
// larger than the disc allows); a full mask gives the whole mask, an empty one nothing.
TEST(ColourRegion, LargestRectangleOfTheAspectInADisc) {
  const int w = 160, h = 120;
  const float R = 50.f, cx = 90.f, cy = 55.f;  // off-centre on purpose
  std::vector<std::uint8_t> disc(w * h), full(w * h, 1), none(w * h, 0);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) disc[y * w + x] = std::hypot(x - cx, y - cy) <= R ? 1 : 0;
  const PixelRect r = largest_rect_of_aspect(disc, w, h);
  EXPECT_NEAR(r.width, 1.6f * R, 2.f);
  EXPECT_NEAR(r.height, 1.2f * R, 2.f);
  EXPECT_NEAR(static_cast<float>(r.width) / r.height, 4.f / 3.f, 0.03f);
  for (int y = r.y; y < r.y + r.height; ++y)
    for (int x = r.x; x < r.x + r.width; ++x) ASSERT_TRUE(disc[y * w + x]) << x << "," << y;
  EXPECT_NEAR(r.x + 0.5f * r.width, cx + 0.5f, 1.f);  // pixel centres x .. x + w - 1 around cx
  const PixelRect f = largest_rect_of_aspect(full, w, h);
  EXPECT_TRUE(f.x == 0 && f.y == 0 && f.width == w && f.height == h);
  EXPECT_TRUE(largest_rect_of_aspect(none, w, h).empty());
}

// Undistorting freiburg1 images leaves a black border (remap_rgb writes 0, 0, 0 where the lens saw
// nothing); input_colour_region is a 4:3 rectangle without it: on the real frames the TUM reader
// delivers, no black pixel inside it, black pixels outside it. Without undistortion (or another
// source) it is empty: the whole image.
TEST(ColourRegion, TumFramesLeaveOutTheUndistortionBorder) {
  std::string dir = data_dir("tum_fr1_rpy_000-149");
  REQUIRE_DATA(dir);
  InputParams p = tum_params(dir);
  p.max_frames = 3;
  const PixelRect r = input_colour_region(p);
  std::printf("colour region %dx%d at (%d, %d)\n", r.width, r.height, r.x, r.y);
  ASSERT_FALSE(r.empty());
  EXPECT_GE(r.x, 0);
  EXPECT_GE(r.y, 0);
  EXPECT_LE(r.x + r.width, 640);
  EXPECT_LE(r.y + r.height, 480);
  EXPECT_NEAR(static_cast<float>(r.width) / r.height, 4.f / 3.f, 0.01f);
  EXPECT_GT(r.width, 500) << "the border is 6-25 pixels wide";
  TumSource src(p);
  RgbdFrame f;
  while (src.next(f)) {
    const std::vector<uchar3> c = f.rgb.to_host();
    int black_in = 0, black_out = 0;
    for (int y = 0; y < 480; ++y)
      for (int x = 0; x < 640; ++x) {
        const uchar3 q = c[y * 640 + x];
        const bool black = q.x == 0 && q.y == 0 && q.z == 0;
        const bool in = x >= r.x && x < r.x + r.width && y >= r.y && y < r.y + r.height;
        (in ? black_in : black_out) += black ? 1 : 0;
      }
    std::printf("black pixels inside %d, outside %d\n", black_in, black_out);
    EXPECT_EQ(black_in, 0);
    EXPECT_GT(black_out, 1000);
  }
  p.undistort = false;
  EXPECT_TRUE(input_colour_region(p).empty());
  p.undistort = true;
  p.source = InputSource::frames;
  EXPECT_TRUE(input_colour_region(p).empty());
}
