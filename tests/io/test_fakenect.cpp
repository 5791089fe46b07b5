// The live Kinect path end to end without hardware: synthetic frames -> fakenect recording ->
// Debian's fakenect libfreenect -> KinectSource (in a child process) -> record() -> compare.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/fakenect_source.hpp"
#include "io/input_params.hpp"
#include "io/kinect_source.hpp"
#include "io/synthetic_source.hpp"
#include "io/tum_source.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {
InputParams room() {
  InputParams p;
  p.synthetic.frames = 5;
  p.synthetic.noise = true;
  return p;
}
}  // namespace

TEST(Fakenect, ReplayedFramesEqualTheSyntheticOnes) {
  std::string lib_dir = SEAMLESS_FAKENECT_DIR;
  if (!std::filesystem::exists(lib_dir + "/libfreenect.so.0.5"))
    GTEST_SKIP() << "fakenect's libfreenect not found (" << lib_dir << "): apt-get install libfreenect-bin";
  TmpDir dir("fakenect");
  SyntheticSource src(room());
  ASSERT_EQ(write_fakenect_dump(src, dir / "dump"), 5);

  std::string cmd = "env FAKENECT_PATH='" + (dir / "dump") + "' LD_LIBRARY_PATH='" + lib_dir + "' '" +
                    SEAMLESS_KINECT_REPLAY + "' '" + (dir / "out") + "' 5 > '" + (dir / "log.txt") + "' 2>&1";
  int rc = std::system(cmd.c_str());
  std::ifstream log(dir / "log.txt");
  std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  ASSERT_EQ(rc, 0) << cmd << "\n" << text;
  EXPECT_NE(text.find("frames 5 dropped 0"), std::string::npos) << text;

  InputParams q;
  q.source = InputSource::tum;
  q.path = dir / "out";
  TumSource replay(q);
  ASSERT_EQ(replay.size(), 5);
  SyntheticSource truth(room());
  RgbdFrame a, b;
  for (int k = 0; k < 5; ++k) {
    ASSERT_TRUE(truth.next(a));
    ASSERT_TRUE(replay.next(b));
    // Registered depth is whole millimetres (0.5 mm rounding), recorded at 1/5000 m (0.1 mm).
    auto za = a.depth.to_host(), zb = b.depth.to_host();
    for (std::size_t i = 0; i < za.size(); ++i) ASSERT_NEAR(za[i], zb[i], 0.5e-3f + 0.1e-3f + 1e-6f) << k << " " << i;
    auto ca = a.rgb.to_host(), cb = b.rgb.to_host();
    for (std::size_t i = 0; i < ca.size(); ++i)
      ASSERT_TRUE(ca[i].x == cb[i].x && ca[i].y == cb[i].y && ca[i].z == cb[i].z);
    // Accelerometer: raw counts of g/819 (half a count of rounding), 6 digits in accelerometer.txt.
    ASSERT_TRUE(b.accelerometer);
    const float count = 9.80665f / 819;
    EXPECT_NEAR(a.accelerometer->x, b.accelerometer->x, 0.5f * count + 1e-4f);
    EXPECT_NEAR(a.accelerometer->y, b.accelerometer->y, 0.5f * count + 1e-4f);
    EXPECT_NEAR(a.accelerometer->z, b.accelerometer->z, 0.5f * count + 1e-4f);
  }
}

TEST(Fakenect, DumpFormatIsWhatFakenectParses) {
  TmpDir dir("fakenect_fmt");
  SyntheticSource src(room());
  ASSERT_EQ(write_fakenect_dump(src, dir / "dump", 2), 2);
  std::ifstream index(dir / "dump/INDEX.txt");
  std::vector<std::string> lines;
  for (std::string l; std::getline(index, l);) lines.push_back(l);
  ASSERT_EQ(lines.size(), 6u);  // a, r, d per frame
  for (const auto& l : lines) {
    char type;
    double t;
    unsigned stamp;
    ASSERT_EQ(std::sscanf(l.c_str(), "%c-%lf-%u-", &type, &t, &stamp), 3) << l;  // fakenect's own parse
    auto size = std::filesystem::file_size(dir.path / "dump" / l);
    if (type == 'd') {
      EXPECT_EQ(size, std::string("P5 640 480 65535\n").size() + 640 * 480 * 2);
    }
    if (type == 'r') {
      EXPECT_EQ(size, std::string("P6 640 480 255\n").size() + 640 * 480 * 3);
    }
    if (type == 'a') {
      EXPECT_EQ(size, 12u);
    }  // sizeof(freenect_raw_tilt_state), checked by fakenect
  }
}

TEST(Fakenect, NoKinectIsAClearError) {
  // The real libfreenect on a machine without a Kinect (CI): a seamless::Error that says so.
  if (std::getenv("FAKENECT_PATH")) GTEST_SKIP() << "running under fakenect";
  InputParams p;
  p.source = InputSource::kinect;
  p.kinect.device_index = 3;  // even with a Kinect plugged in, hardly a fourth one
  try {
    KinectSource k(p);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    std::string m = e.what();
    EXPECT_TRUE(m.find("no Kinect v1 found") != std::string::npos ||
                m.find("could not initialise") != std::string::npos)
        << m;
  }
}

// A real fakenect-record folder (raw 11-bit disparity, little-endian samples, device.json) through
// Debian's fakenect and the live KinectSource in raw mode, against the direct reader
// (FakenectSource) on the same folder: both register with the same calibration and kernels and
// pair colour and accelerometer records by the same rule, so depth differs only by the recording
// (TUM depth PNGs at 1/5000 m: 0.1 mm of rounding), colour is equal and the accelerometer agrees to
// the 6 digits of accelerometer.txt.
TEST(Fakenect, RealRecordingReplayEqualsTheDirectReader) {
  std::string lib_dir = SEAMLESS_FAKENECT_DIR;
  if (!std::filesystem::exists(lib_dir + "/libfreenect.so.0.5"))
    GTEST_SKIP() << "fakenect's libfreenect not found (" << lib_dir << "): apt-get install libfreenect-bin";
  const std::string planes = std::string(SEAMLESS_TEST_DATA) + "/kinect_v1_planes";
  if (!std::filesystem::is_directory(planes)) GTEST_SKIP() << "test data folder " << planes << " is absent";
  TmpDir dir("fakenect_real");
  const int n = 8;
  std::string cmd = "env FAKENECT_PATH='" + planes + "' LD_LIBRARY_PATH='" + lib_dir + "' '" + SEAMLESS_KINECT_REPLAY +
                    "' '" + (dir / "out") + "' " + std::to_string(n) + " > '" + (dir / "log.txt") + "' 2>&1";
  int rc = std::system(cmd.c_str());
  std::ifstream log(dir / "log.txt");
  std::string text((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
  ASSERT_EQ(rc, 0) << cmd << "\n" << text;
  EXPECT_NE(text.find("frames " + std::to_string(n) + " dropped 0"), std::string::npos) << text;
  EXPECT_NE(text.find("stored little-endian"), std::string::npos) << text;

  InputParams q;
  q.source = InputSource::tum;
  q.path = dir / "out";
  TumSource replay(q);
  InputParams p;
  p.source = InputSource::fakenect;
  p.path = planes;
  p.max_frames = n;
  FakenectSource direct(p);
  ASSERT_EQ(replay.size(), n);
  ASSERT_EQ(direct.size(), n);
  RgbdFrame a, b;
  for (int k = 0; k < n; ++k) {
    ASSERT_TRUE(direct.next(a));
    ASSERT_TRUE(replay.next(b));
    auto za = a.depth.to_host(), zb = b.depth.to_host();
    for (std::size_t i = 0; i < za.size(); ++i) ASSERT_NEAR(za[i], zb[i], 0.1e-3f + 1e-6f) << k << " " << i;
    auto ca = a.rgb.to_host(), cb = b.rgb.to_host();
    for (std::size_t i = 0; i < ca.size(); ++i)
      ASSERT_TRUE(ca[i].x == cb[i].x && ca[i].y == cb[i].y && ca[i].z == cb[i].z) << k << " " << i;
    ASSERT_EQ(a.accelerometer.has_value(), b.accelerometer.has_value()) << k;
    if (a.accelerometer) {
      EXPECT_NEAR(a.accelerometer->y, b.accelerometer->y, 1e-4f) << k;
      EXPECT_NEAR(a.accelerometer->z, b.accelerometer->z, 1e-4f) << k;
    }
  }
}
