// The Kinect v1 raw-depth model (io/kinect_model.hpp, kernels/io/kinect_depth.hpp) and the direct
// reader of fakenect-record folders (io/fakenect_source.hpp), against libfreenect's own output on
// the real recording ../shared/data/kinect_v1_planes and against hand-made bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <sstream>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "io/fakenect_source.hpp"
#include "io/frame_source.hpp"
#include "io/kinect_model.hpp"
#include "kernels/io/kinect_depth.hpp"
#include "tmp_dir.hpp"

using namespace seamless;
namespace fs = std::filesystem;

namespace {

const std::string kPlanes = data_dir("kinect_v1_planes");

// The recording's files in INDEX.txt order.
std::vector<std::string> index_lines(const std::string& dir) {
  std::ifstream in(dir + "/INDEX.txt");
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);)
    if (!l.empty()) lines.push_back(l);
  return lines;
}

// A fakenect folder in `dst` holding the real recording's first `n` INDEX lines whose type is in
// `types`, plus its device.json.
void copy_recording(const std::string& dst, std::size_t n, const std::string& types = "dra") {
  fs::create_directories(dst);
  std::ofstream index(dst + "/INDEX.txt");
  std::size_t k = 0;
  for (const auto& l : index_lines(kPlanes)) {
    if (k++ >= n) break;
    if (types.find(l[0]) == std::string::npos) continue;
    fs::copy_file(kPlanes + "/" + l, dst + "/" + l, fs::copy_options::overwrite_existing);
    index << l << "\n";
  }
  fs::copy_file(kPlanes + "/device.json", dst + "/device.json", fs::copy_options::overwrite_existing);
}

InputParams fakenect_params(const std::string& dir) {
  InputParams p;
  p.source = InputSource::fakenect;
  p.path = dir;
  return p;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

// libfreenect's raw-to-millimetre conversion, as its registration.c documents it:
// z = 10 R (m R / (E - m) + R) with m = (raw / 4 - c - 3/8) p: in this form, independent of the
// inverse-depth form the kernel evaluates.
double libfreenect_mm(int raw, const KinectCalibration& c) {
  const double m = (raw / 4.0 - c.const_shift - 0.375) * c.reference_pixel_size;
  return 10 * (m * c.reference_distance / (c.emitter_cm - m) + c.reference_distance);
}

}  // namespace

TEST(KinectModel, DisparityToMetresMatchesLibfreenect) {
  REQUIRE_DATA(kPlanes);
  const KinectCalibration c = read_kinect_device_json(kPlanes + "/device.json");
  EXPECT_EQ(c.const_shift, 200);
  EXPECT_EQ(c.dx_start, 3269);
  const kernels::KinectDisparityModel m = kinect_disparity_model(c);
  // libfreenect 0.7.5's FREENECT_DEPTH_MM output on this recording, raw -> millimetres, read off
  // frames replayed through its fakenect with this device.json (tests/io/data/README.md). It
  // truncates to whole millimetres: ours lies within [0, 1) mm above, plus float rounding (1e-6
  // relative: 6 um at 6 m).
  const int pairs[][2] = {{403, 503},  {437, 529},   {500, 586},   {600, 705},  {700, 887},
                          {800, 1193}, {1000, 3864}, {1025, 5364}, {1033, 6124}};
  for (const auto& p : pairs) {
    const float z = kernels::kinect_raw_to_metres(m, static_cast<std::uint16_t>(p[0]));
    EXPECT_GE(z * 1000.0, p[1] - 0.01) << p[0];
    EXPECT_LT(z * 1000.0, p[1] + 1.01) << p[0];
  }
  // The whole valid range against the documented formula, to float rounding.
  for (int raw = 0; raw < 2047; ++raw) {
    const double want = libfreenect_mm(raw, c) / 1000.0;
    const float z = kernels::kinect_raw_to_metres(m, static_cast<std::uint16_t>(raw));
    if (want <= 0 || want > 10.0) {
      EXPECT_EQ(z, 0.f) << raw;  // no reading: behind the emitter's asymptote or beyond 10 m
    } else if (want < 9.99) {
      EXPECT_NEAR(z, want, 2e-6 * want) << raw;
    }
  }
  EXPECT_EQ(kernels::kinect_raw_to_metres(m, 2047), 0.f);
  // SOURCE.txt's figures for this unit: raw 437 = 0.53 m, 700 = 0.89 m, 1025 = 5.4 m.
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 437), 0.53, 0.005);
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 700), 0.89, 0.005);
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 1025), 5.4, 0.05);
}

TEST(KinectModel, DefaultsAreAKinect) {
  // The built-in unit: IR focal length 120 / (2 x 0.1042) = 575.8 px, the colour camera 2.4 cm away,
  // raw 700 at libfreenect's 887 mm (truncated), and a rectification that keeps 90% of the depth
  // image inside the colour frame.
  float f = 0;
  const auto m = kinect_disparity_model(kinect_default_calibration(), &f);
  EXPECT_NEAR(f, 575.8, 0.1);
  EXPECT_NEAR(m.fb, 575.8 * 0.024, 0.01);
  EXPECT_NEAR(kernels::kinect_raw_to_metres(m, 700), 0.8875, 0.0006);
  const auto t = kinect_registration_table(kinect_default_calibration());
  std::size_t inside = 0;
  for (const auto& v : t) inside += v.x >= 0;
  EXPECT_GT(inside, t.size() * 9 / 10);
}

TEST(KinectModel, ByteOrderIsToldByTheValues) {
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> u(402, 1036);
  std::vector<std::uint16_t> v(1000);
  for (auto& x : v) x = static_cast<std::uint16_t>(u(rng) < 500 ? 2047 : u(rng));
  std::vector<std::uint8_t> le(2000), be(2000);
  for (std::size_t i = 0; i < v.size(); ++i) {
    le[2 * i] = v[i] & 0xff, le[2 * i + 1] = v[i] >> 8;
    be[2 * i] = v[i] >> 8, be[2 * i + 1] = v[i] & 0xff;
  }
  EXPECT_EQ(kinect_sample_order(le.data(), v.size(), "x"), SampleOrder::little_endian);
  EXPECT_EQ(kinect_sample_order(be.data(), v.size(), "x"), SampleOrder::big_endian);
  // Only tiny values (both bytes below 8) fit either way: the PGM standard, big-endian.
  std::vector<std::uint8_t> tiny = {0, 3, 7, 0};
  EXPECT_EQ(kinect_sample_order(tiny.data(), 2, "x"), SampleOrder::big_endian);
  // Millimetres (3000 = 0x0BB8) fit neither: an error naming the file.
  std::vector<std::uint8_t> mm = {0xB8, 0x0B, 0x0B, 0xB8};
  std::string msg = error_of([&] { kinect_sample_order(mm.data(), 2, "d-1.pgm"); });
  EXPECT_MENTIONS(msg, "d-1.pgm");
  EXPECT_MENTIONS(msg, "not raw 11-bit");
}

TEST(KinectModel, ColourPairingTakesTheNearerFrameAcrossTheClockWrap) {
  EXPECT_FALSE(kinect_next_colour_is_nearer(1000, 900, 1200));
  EXPECT_TRUE(kinect_next_colour_is_nearer(1000, 700, 1200));
  EXPECT_FALSE(kinect_next_colour_is_nearer(1000, 800, 1200));             // a tie: the earlier
  EXPECT_TRUE(kinect_next_colour_is_nearer(0xfffffff0u, 0xffff0000u, 5));  // wrapped clock
}

TEST(KinectModel, AccelerometerCountsToCameraFrame) {
  // This recording's mean counts (2.6, 811.9, 22.8): gravity (ax, ay, -az) points down (+y) and a
  // little back, so the specific force points up (-y), magnitude 0.99 g.
  const vec3 a = kinect_accel_to_camera(3, 812, 23);
  EXPECT_NEAR(a.y, -812 * 9.80665 / 819, 1e-4);
  EXPECT_NEAR(a.z, 23 * 9.80665 / 819, 1e-4);
  EXPECT_NEAR(a.x, -3 * 9.80665 / 819, 1e-4);
}

// The registered first frame against libfreenect 0.7.5's FREENECT_DEPTH_REGISTERED output for it
// (every 8th pixel, tests/io/data). Both put each depth pixel at floor(u) of (2) in
// kernels/io/kinect_depth.hpp; libfreenect in 1/256-pixel fixed point from whole-millimetre
// depth, we in float from the exact depth, so a pixel lands in the neighbouring column where u
// is within about 1/128 pixel of a column border: about 1% of the pixels. Where both land on the
// same pixel the depths differ by libfreenect's truncation, under 1 mm.
TEST(KinectRegistration, RealFrameMatchesLibfreenect) {
  REQUIRE_DATA(kPlanes);
  std::ifstream ref(std::string(SEAMLESS_TEST_SOURCE_DIR) + "/data/kinect_v1_planes_registered_frame0.txt");
  ASSERT_TRUE(ref);
  std::vector<int> want;
  for (std::string l; std::getline(ref, l);) {
    if (l.empty() || l[0] == '#') continue;
    std::istringstream s(l);
    for (int v; s >> v;) want.push_back(v);
  }
  ASSERT_EQ(want.size(), 60u * 80u);
  FakenectSource src(fakenect_params(kPlanes));
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  const auto z = f.depth.to_host();
  int both = 0, same = 0, only_ours = 0, only_theirs = 0;
  for (int r = 0; r < 60; ++r)
    for (int c = 0; c < 80; ++c) {
      const int w = want[r * 80 + c];
      const float ours = z[(r * 8) * 640 + c * 8] * 1000.f;
      if (w > 0 && ours > 0) {
        ++both;
        same += ours - w >= -0.01f && ours - w < 1.01f;
      }
      only_ours += w == 0 && ours > 0;
      only_theirs += w > 0 && ours == 0;
    }
  std::printf("sampled pixels: both %d (same depth %d), only ours %d, only libfreenect %d\n", both, same, only_ours,
              only_theirs);
  EXPECT_GT(both, 2000);  // about 55% of 4800 have a registered depth
  EXPECT_GE(same, both * 97 / 100);
  EXPECT_LE(only_ours + only_theirs, both * 3 / 100);
}

TEST(Fakenect, RealRecordingReadDirectly) {
  REQUIRE_DATA(kPlanes);
  FakenectSource src(fakenect_params(kPlanes));
  ASSERT_EQ(src.size(), 20);
  RgbdFrame f;
  int n = 0;
  while (src.next(f)) {
    ++n;
    ASSERT_TRUE(f.accelerometer) << n;
    const vec3 a = *f.accelerometer;
    // SOURCE.txt: the camera stands upright, pitched ~1.6 degrees, |a| 0.99 g over these frames.
    const float g = std::sqrt(a.x * a.x + a.y * a.y + a.z * a.z);
    EXPECT_NEAR(g, 9.72, 0.3);
    EXPECT_LT(a.y, -0.98f * g);
    const auto z = f.depth.to_host();
    std::size_t valid = 0;
    for (float v : z) valid += v > 0;
    // 64% of the raw pixels have a reading; registration drops those mapped outside the colour
    // image and the ones hidden behind nearer ones: about 55% remain.
    EXPECT_GT(valid, z.size() * 45 / 100);
    EXPECT_LT(valid, z.size() * 65 / 100);
  }
  EXPECT_EQ(n, 20);
}

TEST(Fakenect, FolderDetectedByIndex) {
  REQUIRE_DATA(kPlanes);
  InputParams p = fakenect_params(kPlanes);
  p.source = InputSource::tum;
  p.max_frames = 2;
  auto src = make_source(p);
  EXPECT_EQ(src->size(), 2);
  EXPECT_EQ(src->name(), "fakenect:" + kPlanes);
}

TEST(FakenectBadInput, NotAFakenectFolder) {
  TmpDir dir("fakenect_none");
  std::string msg = error_of([&] { FakenectSource s(fakenect_params(dir.str())); });
  EXPECT_MENTIONS(msg, dir.str());
  EXPECT_MENTIONS(msg, "no INDEX.txt");
  std::ofstream(dir / "INDEX.txt") << "hello\n";
  msg = error_of([&] { FakenectSource s(fakenect_params(dir.str())); });
  EXPECT_MENTIONS(msg, "INDEX.txt line 1 'hello'");
}

TEST(FakenectBadInput, TruncatedAndMissingDepth) {
  REQUIRE_DATA(kPlanes);
  TmpDir dir("fakenect_trunc");
  copy_recording(dir.str(), 6);
  const auto lines = index_lines(dir.str());
  const std::string d = dir / lines[1];
  ASSERT_EQ(lines[1][0], 'd');
  fs::resize_file(d, 1000);
  FakenectSource s(fakenect_params(dir.str()));
  RgbdFrame f;
  std::string msg = error_of([&] { s.next(f); });
  EXPECT_MENTIONS(msg, d);
  EXPECT_MENTIONS(msg, "truncated");
  fs::remove(d);
  FakenectSource s2(fakenect_params(dir.str()));
  msg = error_of([&] { s2.next(f); });
  EXPECT_MENTIONS(msg, d);
  // skip_bad_frames: the frame is left out with a warning, the next one is read.
  InputParams p = fakenect_params(dir.str());
  p.skip_bad_frames = true;
  FakenectSource s3(p);
  EXPECT_TRUE(s3.next(f));
  EXPECT_EQ(s3.skipped_frames(), 1);
}

TEST(FakenectBadInput, NoColourOrNoAccelerometerFallsBack) {
  REQUIRE_DATA(kPlanes);
  TmpDir dir("fakenect_parts");
  copy_recording(dir / "depth_only", 12, "d");
  FakenectSource a(fakenect_params(dir / "depth_only"));
  RgbdFrame f;
  ASSERT_TRUE(a.next(f));
  EXPECT_EQ(f.rgb.to_host()[1000].x, 128);  // the documented grey
  EXPECT_FALSE(f.accelerometer);
  copy_recording(dir / "no_accel", 12, "dr");
  FakenectSource b(fakenect_params(dir / "no_accel"));
  ASSERT_TRUE(b.next(f));
  EXPECT_FALSE(f.accelerometer);
  copy_recording(dir / "no_depth", 12, "ra");
  std::string msg = error_of([&] { FakenectSource c(fakenect_params(dir / "no_depth")); });
  EXPECT_MENTIONS(msg, "no depth record");
  // A broken device.json names the file and the key.
  copy_recording(dir / "bad_json", 6);
  std::ofstream(dir / "bad_json/device.json") << "{\"reg_info\": {\"ax\": 1}}";
  msg = error_of([&] { FakenectSource c(fakenect_params(dir / "bad_json")); });
  EXPECT_MENTIONS(msg, "device.json");
  EXPECT_MENTIONS(msg, "reg_info.bx");
  // Without device.json: the defaults, with a warning.
  fs::remove(dir / "bad_json/device.json");
  FakenectSource d(fakenect_params(dir / "bad_json"));
  EXPECT_TRUE(d.next(f));
}
