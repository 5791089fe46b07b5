// Frame folders (input.source: frames): the real tsdf-fusion sample in /work/shared/data and small
// folders written here for what that sample lacks (JPEG colour, gaps, missing files, other
// intrinsics file names, gravity-direction.txt).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/depth_scale.hpp"
#include "io/frame_folder_source.hpp"
#include "io/input_params.hpp"
#include "io/jpeg_io.hpp"
#include "io/png_io.hpp"
#include "tmp_dir.hpp"

using namespace seamless;
namespace fs = std::filesystem;

namespace {

InputParams frames_params(const std::string& dir) {
  InputParams p;
  p.source = InputSource::frames;
  p.path = dir;
  return p;
}

// The 16 numbers of a pose file, as the file has them (independent of read_pose_matrix).
std::vector<double> file_numbers(const std::string& path) {
  std::ifstream in(path);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

std::string name(int n, const char* kind) {
  char b[64];
  std::snprintf(b, sizeof b, "frame-%06d.%s", n, kind);
  return b;
}

// A small frame folder: W x H frames of a tilted plane (depth 1.2 .. 1.83 m across, millimetres)
// and a colour gradient that differs per frame.
struct Fixture {
  static constexpr int W = 64, H = 48;
  TmpDir dir;
  explicit Fixture(const std::string& tag) : dir(tag) {}
  static std::uint16_t depth_mm(int x, int) { return static_cast<std::uint16_t>(1200 + 10 * x); }
  static uchar3 colour(int x, int y, int n) {
    return {static_cast<std::uint8_t>(4 * x), static_cast<std::uint8_t>(5 * y), static_cast<std::uint8_t>(n % 256)};
  }
  Image<uchar3> colour_image(int n) const {
    Image<uchar3> c(W, H, Device::CPU);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) c.buffer().data()[y * W + x] = colour(x, y, n);
    return c;
  }
  void depth(int n) const {
    Image<std::uint16_t> d(W, H, Device::CPU);
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) d.buffer().data()[y * W + x] = depth_mm(x, y);
    write_png_u16(dir / name(n, "depth.png"), d);
  }
  void colour(int n, const char* kind = "color.png") const {
    if (std::string(kind).find("jpg") != std::string::npos) write_jpeg_rgb(dir / name(n, kind), colour_image(n), 100);
    else write_png_rgb(dir / name(n, kind), colour_image(n));
  }
  void pose(int n, const std::string& text) const { std::ofstream(dir / name(n, "pose.txt")) << text; }
  void frame(int n) const {
    depth(n);
    colour(n);
    pose(n, "1 0 0 " + std::to_string(0.01 * n) + "\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  }
  InputParams params() const {
    InputParams p = frames_params(dir.str());
    p.intrinsics.width = W;
    p.intrinsics.height = H;
    return p;
  }
};

std::string error_of(const InputParams& p) {
  try {
    FrameFolderSource src(p);
    RgbdFrame f;
    while (src.next(f)) {
    }
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// ---- the real sample ----------------------------------------------------------------------------

TEST(FrameFolder, RealSampleFramesIntrinsicsDepthAndPoses) {
  const std::string dir = data_dir("frames_box_50");
  REQUIRE_DATA(dir);
  auto src_any = make_source(frames_params(dir));
  auto* src = dynamic_cast<FrameFolderSource*>(src_any.get());
  ASSERT_NE(src, nullptr);
  ASSERT_EQ(src->size(), 50);
  // Every second frame from 15 (SOURCE.txt): listed and sorted by number.
  for (std::size_t i = 0; i < src->frames().size(); ++i) EXPECT_EQ(src->frames()[i].number, 15 + 2 * i);
  // intrinsics.K.txt: 615.1951904296875 0 298.44268798828125 / 0 615.19525146484375 247.51919555664062.
  const Intrinsics K = src->intrinsics();
  EXPECT_FLOAT_EQ(K.fx, 615.1951904296875f);
  EXPECT_FLOAT_EQ(K.fy, 615.19525146484375f);
  EXPECT_FLOAT_EQ(K.cx, 298.44268798828125f);
  EXPECT_FLOAT_EQ(K.cy, 247.51919555664062f);
  EXPECT_EQ(K.width, 640);
  EXPECT_FALSE(src->gravity_direction());
  RgbdFrame f;
  int n = 0;
  while (src->next(f)) {
    const FrameFolderEntry& e = src->frames()[n];
    EXPECT_EQ(f.index, n);
    EXPECT_DOUBLE_EQ(f.timestamp, e.number / 30.0);  // no timestamps in the folder: number / 30 fps
    ASSERT_TRUE(f.ground_truth);
    EXPECT_FALSE(f.accelerometer);  // no gravity-direction.txt
    // The pose is the file's matrix (camera to world), to float rounding.
    std::vector<double> m = file_numbers(dir + "/" + e.pose);
    ASSERT_EQ(m.size(), 16u);
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(f.ground_truth->R.m[r][c], m[4 * r + c], 1e-6) << e.pose;
    }
    EXPECT_NEAR(f.ground_truth->t.x, m[3], 1e-6);
    EXPECT_NEAR(f.ground_truth->t.y, m[7], 1e-6);
    EXPECT_NEAR(f.ground_truth->t.z, m[11], 1e-6);
    if (n == 0) {
      // Hand-checked in frame-000015.depth.png: pixel (300, 200) holds 394, (305, 200) 395, (310,
      // 200) 0 (a gap): millimetres, so 0.394 m and 0.395 m: the box on the table 0.4 m away.
      EXPECT_FLOAT_EQ(f.depth.buffer().data()[200 * 640 + 300], 0.394f);
      EXPECT_FLOAT_EQ(f.depth.buffer().data()[200 * 640 + 305], 0.395f);
      EXPECT_EQ(f.depth.buffer().data()[200 * 640 + 310], 0.f);
      EXPECT_NEAR(median_depth(f.depth), 0.41, 0.02);  // SOURCE.txt: median ~0.41 m
      // The colour is the PNG as written.
      std::vector<uchar3> want = read_png_rgb(dir + "/frame-000015.color.png").to_host(), got = f.rgb.to_host();
      ASSERT_EQ(want.size(), got.size());
      for (std::size_t i = 0; i < want.size(); i += 101) EXPECT_EQ(got[i].x, want[i].x);
      // The sample's depth was registered by forward projection: about a quarter of the pixels are
      // one-pixel gaps between agreeing depths (what input.fill_gaps closes).
      double gaps = fillable_gap_fraction(f.depth);
      EXPECT_GT(gaps, 0.2);
      EXPECT_LT(gaps, 0.35);
    }
    ++n;
  }
  EXPECT_EQ(n, 50);
  EXPECT_EQ(src->skipped_frames(), 0);
}

TEST(FrameFolder, RealSampleFillGapsKeepsMeasuredDepth) {
  const std::string dir = data_dir("frames_box_50");
  REQUIRE_DATA(dir);
  InputParams p = frames_params(dir);
  p.max_frames = 1;
  FrameFolderSource raw_src(p);
  p.fill_gaps = true;
  FrameFolderSource filled_src(p);
  RgbdFrame a, b;
  ASSERT_TRUE(raw_src.next(a));
  ASSERT_TRUE(filled_src.next(b));
  std::vector<float> ra = a.depth.to_host(), rb = b.depth.to_host();
  std::int64_t raw_valid = 0, filled_valid = 0;
  const int w = 640;
  for (std::size_t i = 0; i < ra.size(); ++i) {
    raw_valid += ra[i] > 0;
    filled_valid += rb[i] > 0;
    if (ra[i] > 0) {
      EXPECT_EQ(rb[i], ra[i]);  // a measurement is never changed
    } else if (rb[i] > 0) {
      // A filled gap is a mean of measured neighbours: within their range (to the float rounding of
      // the mean, 1e-6 m).
      const int x = static_cast<int>(i % w), y = static_cast<int>(i / w);
      float lo = 1e9f, hi = 0.f;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || x + dx >= w || y + dy < 0 || y + dy >= 480) continue;
          const float v = ra[(y + dy) * w + (x + dx)];
          if (v > 0) lo = std::min(lo, v), hi = std::max(hi, v);
        }
      EXPECT_GE(rb[i], lo - 1e-6f);
      EXPECT_LE(rb[i], hi + 1e-6f);
    }
  }
  // About a quarter of the image was gaps (RealSampleFramesIntrinsicsDepthAndPoses).
  EXPECT_GT(filled_valid, raw_valid + static_cast<std::int64_t>(0.2 * ra.size()));
  // Hand-checked: (102, 300) is a gap between 0.323 m at (101, 300) and 0.321 m at (103, 300).
  EXPECT_EQ(a.depth.buffer().data()[300 * 640 + 102], 0.f);
  EXPECT_NEAR(b.depth.buffer().data()[300 * 640 + 102], 0.322f, 0.002f);
}

// ---- synthetic folders --------------------------------------------------------------------------

TEST(FrameFolder, GapsInNumberingAreSortedByNumber) {
  Fixture fx("frames_gaps");
  for (int n : {7, 3, 120, 12, 1000})  // written out of order; listed in any order by the OS
    fx.frame(n);
  std::ofstream(fx.dir / "frame-notes.txt") << "not a frame";  // ignored
  InputParams p = fx.params();
  p.fps = 10;
  FrameFolderSource src(p);
  ASSERT_EQ(src.size(), 5);
  const std::int64_t want[] = {3, 7, 12, 120, 1000};
  RgbdFrame f;
  for (std::int64_t n : want) {
    ASSERT_TRUE(src.next(f));
    EXPECT_DOUBLE_EQ(f.timestamp, n / 10.0);
    ASSERT_TRUE(f.ground_truth);
    EXPECT_FLOAT_EQ(f.ground_truth->t.x, static_cast<float>(0.01 * n));  // this frame's own pose
    EXPECT_EQ(f.rgb.buffer().data()[0].z, n % 256);                      // ... and colour
  }
  EXPECT_FALSE(src.next(f));
  // first_frame / max_frames count frames in that order, not frame numbers.
  p.first_frame = 1;
  p.max_frames = 2;
  FrameFolderSource window(p);
  ASSERT_EQ(window.size(), 2);
  EXPECT_EQ(window.frames()[0].number, 7);
  EXPECT_EQ(window.frames()[1].number, 12);
}

TEST(FrameFolder, JpegColourAndDepthInMillimetresByDefault) {
  Fixture fx("frames_jpeg");
  fx.depth(0);
  fx.colour(0, "color.jpg");
  fx.depth(1);
  fx.colour(1, "color.jpeg");
  InputParams p = fx.params();
  FrameFolderSource src(p);
  RgbdFrame f;
  for (int n = 0; n < 2; ++n) {
    ASSERT_TRUE(src.next(f));
    EXPECT_FALSE(f.ground_truth);  // no pose files
    // input.depth_scale 0: the layout's millimetres.
    EXPECT_FLOAT_EQ(f.depth.buffer().data()[5 * Fixture::W + 20], Fixture::depth_mm(20, 5) / 1000.f);
    // JPEG at quality 100 (all quantisation steps 1) of a smooth gradient: within a few levels
    // (rounding of the DCT coefficients and of the colour conversion; 4:2:0 chroma is exact on a
    // gradient up to the same rounding). 4 levels leaves room for both, far below any real error.
    const Image<uchar3> want = fx.colour_image(n);
    int worst = 0;
    for (std::int64_t i = 0; i < want.buffer().size(); ++i) {
      uchar3 a = want.buffer().data()[i], b = f.rgb.buffer().data()[i];
      worst = std::max({worst, std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)});
    }
    EXPECT_LE(worst, 4);
  }
  // An explicit depth_scale wins over the layout's.
  p.depth_scale = 2000;
  FrameFolderSource half(p);
  ASSERT_TRUE(half.next(f));
  EXPECT_FLOAT_EQ(f.depth.buffer().data()[20], Fixture::depth_mm(20, 0) / 2000.f);
}

TEST(FrameFolder, MissingDepthIsAClearError) {
  Fixture fx("frames_missing");
  fx.frame(0);
  fx.colour(1);  // no depth for frame 1
  fx.frame(2);
  const std::string msg = error_of(fx.params());
  EXPECT_MENTIONS(msg, "frame 1 has no depth image frame-000001.depth.png");
  EXPECT_MENTIONS(msg, fx.dir.str());
  EXPECT_MENTIONS(msg, "skip_bad_frames");
  // Skipping is allowed and counted.
  InputParams p = fx.params();
  p.skip_bad_frames = true;
  FrameFolderSource src(p);
  EXPECT_EQ(src.size(), 2);
  EXPECT_EQ(src.skipped_frames(), 1);
  // A depth image without colour, likewise.
  fs::remove(fx.dir / name(1, "color.png"));
  fx.depth(1);
  fs::remove(fx.dir / name(0, "color.png"));
  EXPECT_MENTIONS(error_of(fx.params()), "frame 0 has no colour image");
  // Two colour images for one frame: which one?
  fx.colour(2, "color.jpg");
  EXPECT_MENTIONS(error_of(fx.params()), "two colour images for frame 2");
}

TEST(FrameFolder, NoReadingMarkersAndLostPoses) {
  Fixture fx("frames_markers");
  fx.frame(0);
  fx.frame(1);
  Image<std::uint16_t> d = read_png_u16(fx.dir / name(0, "depth.png"));
  d.buffer().data()[3] = 65535;  // 7-Scenes marks "no reading" so
  write_png_u16(fx.dir / name(0, "depth.png"), d);
  fx.pose(1, "-inf -inf -inf -inf\n-inf -inf -inf -inf\n-inf -inf -inf -inf\n-inf -inf -inf -inf\n");  // ScanNet: lost
  FrameFolderSource src(fx.params());
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  EXPECT_EQ(f.depth.buffer().data()[3], 0.f);
  EXPECT_TRUE(f.ground_truth);
  ASSERT_TRUE(src.next(f));
  EXPECT_FALSE(f.ground_truth);
}

TEST(FrameFolder, BadPoseFilesNameTheFileAndTheProblem) {
  Fixture fx("frames_badpose");
  fx.frame(0);
  const std::string file = fx.dir / name(0, "pose.txt");
  fx.pose(0, "1 0 0 0\n0 1 0 0\n0 0 1 0\n0.5 0.2 0.1 1\n");  // transposed: translation in the last row
  std::string msg = error_of(fx.params());
  EXPECT_MENTIONS(msg, file);
  EXPECT_MENTIONS(msg, "bottom row");
  fx.pose(0, "1 0 0 0\n0 1 0 0\n0 0 1 0\n");
  EXPECT_MENTIONS(error_of(fx.params()), "holds 12 numbers");
  fx.pose(0, "2 0 0 0\n0 2 0 0\n0 0 2 0\n0 0 0 1\n");  // scaled: not a rotation
  EXPECT_MENTIONS(error_of(fx.params()), "not a rotation");
  fx.pose(0, "1 0 0 0\n0 1 0 0\n0 0 x 0\n0 0 0 1\n");
  msg = error_of(fx.params());
  EXPECT_MENTIONS(msg, "line 3");
  EXPECT_MENTIONS(msg, "'x' is not a number");
  // A rotation saved with few digits (0.7071 for 1/sqrt 2) is brought back onto SO(3).
  fx.pose(0, "0.7071 -0.7071 0 0\n0.7071 0.7071 0 0\n0 0 1 0\n0 0 0 1\n");
  FrameFolderSource src(fx.params());
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  const mat3 RtR = transpose(f.ground_truth->R) * f.ground_truth->R;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(RtR.m[r][c], r == c ? 1.0 : 0.0, 1e-6);
  EXPECT_NEAR(f.ground_truth->R.m[0][0], std::sqrt(0.5), 1e-5);
}

TEST(FrameFolder, IntrinsicsFromCameraIntrinsicsTxtHereOrInTheParent) {
  Fixture fx("frames_k");
  const fs::path seq = fx.dir.path / "seq-01";  // 3DMatch / 7-Scenes: one K per scene, above its sequences
  fs::create_directories(seq);
  // The frames in seq-01; camera-intrinsics.txt in the scene folder, tab-separated, scientific.
  for (int n = 0; n < 2; ++n) {
    Image<std::uint16_t> depth(Fixture::W, Fixture::H, Device::CPU);
    for (int i = 0; i < Fixture::W * Fixture::H; ++i) depth.buffer().data()[i] = 1500;
    write_png_u16((seq / name(n, "depth.png")).string(), depth);
    write_png_rgb((seq / name(n, "color.png")).string(), fx.colour_image(n));
  }
  std::ofstream(fx.dir / "camera-intrinsics.txt") << "5.85e+02\t0\t3.2e+01\n0\t5.85e+02\t2.4e+01\n0\t0\t1\n";
  InputParams p = fx.params();
  p.path = seq.string();
  {
    FrameFolderSource src(p);
    EXPECT_FLOAT_EQ(src.intrinsics().fx, 585.f);
    EXPECT_FLOAT_EQ(src.intrinsics().cx, 32.f);
    EXPECT_FLOAT_EQ(src.intrinsics().cy, 24.f);
    RgbdFrame f;
    ASSERT_TRUE(src.next(f));
    EXPECT_FLOAT_EQ(f.intrinsics.fy, 585.f);  // and the frames carry them
  }
  // One in the folder itself comes first; intrinsics.K.txt is the other name.
  std::ofstream(seq / "intrinsics.K.txt") << "600 0 31.5\n0 601 23.5\n0 0 1\n";
  EXPECT_FLOAT_EQ(FrameFolderSource(p).intrinsics().fy, 601.f);
  // An explicit preset wins over the files.
  p.intrinsics.preset = "kinect_v1";
  EXPECT_FLOAT_EQ(FrameFolderSource(p).intrinsics().fx, 525.f);
  p.intrinsics.preset = "auto";
  // A malformed K names the file.
  std::ofstream(seq / "intrinsics.K.txt") << "600 0 31.5\n0 601 23.5\n";
  std::string msg = error_of(p);
  EXPECT_MENTIONS(msg, "intrinsics.K.txt");
  EXPECT_MENTIONS(msg, "holds 6 numbers");
  std::ofstream(seq / "intrinsics.K.txt") << "600 0 0\n0 601 0\n31.5 23.5 1\n";  // transposed
  EXPECT_MENTIONS(error_of(p), "bottom row is not 0 0 1");
  // None anywhere: the kinect_v1 preset (logged with a warning saying so).
  fs::remove(seq / "intrinsics.K.txt");
  fs::remove(fx.dir / "camera-intrinsics.txt");
  EXPECT_FLOAT_EQ(FrameFolderSource(p).intrinsics().fx, 525.f);
}

TEST(FrameFolder, GravityDirectionBecomesEachFramesAccelerometer) {
  Fixture fx("frames_gravity");
  fx.frame(0);
  fx.frame(1);
  // Frame 1 turned 90 degrees about the world x axis: camera y = world z, camera z = world -y.
  fx.pose(1, "1 0 0 0.1\n0 0 -1 0\n0 1 0 0\n0 0 0 1\n");
  std::ofstream(fx.dir / "gravity-direction.txt") << " 0.0\n 0.98\n 0.2\n";  // 7-Scenes' format, not unit
  FrameFolderSource src(fx.params());
  ASSERT_TRUE(src.gravity_direction());
  const vec3 g = *src.gravity_direction();
  EXPECT_NEAR(length(g), 1.0, 1e-6);
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  ASSERT_TRUE(f.accelerometer);
  // Identity pose: the specific force at rest is -9.80665 times gravity's direction.
  EXPECT_NEAR(f.accelerometer->x, 0.0, 1e-5);
  EXPECT_NEAR(f.accelerometer->y, -9.80665 * 0.98 / std::hypot(0.98, 0.2), 1e-4);
  EXPECT_NEAR(f.accelerometer->z, -9.80665 * 0.2 / std::hypot(0.98, 0.2), 1e-4);
  ASSERT_TRUE(src.next(f));
  ASSERT_TRUE(f.accelerometer);
  // In frame 1's camera: R^T g with R's columns the camera axes in the world: (g.x, g.z, -g.y).
  EXPECT_NEAR(f.accelerometer->x, 0.0, 1e-5);
  EXPECT_NEAR(f.accelerometer->y, -9.80665 * g.z, 1e-4);
  EXPECT_NEAR(f.accelerometer->z, 9.80665 * g.y, 1e-4);
  // Malformed: named.
  std::ofstream(fx.dir / "gravity-direction.txt") << "0 0\n";
  EXPECT_MENTIONS(error_of(fx.params()), "gravity-direction.txt' holds 2 numbers");
}

TEST(FrameFolder, EmptyOrMissingFolder) {
  TmpDir empty("frames_empty");
  EXPECT_MENTIONS(error_of(frames_params(empty.str())), "has no frames");
  EXPECT_MENTIONS(error_of(frames_params(empty / "nope")), "is not a folder");
  EXPECT_MENTIONS(error_of(frames_params("")), "input.path is empty");
}
