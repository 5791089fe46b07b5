// input.intrinsics.file (io/camera_file.hpp): camera files as ORB-SLAM, OpenCV, ROS and Open3D
// write them, small hand-written copies of their layouts with known values; the errors name the
// file and what is missing; a negative focal length (ICL-NUIM's fy = -480) read as a flipped image
// sees the same 3D points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/camera_file.hpp"
#include "io/frame_folder_source.hpp"
#include "io/input_params.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/png_io.hpp"
#include "tmp_dir.hpp"

using namespace seamless;

namespace {

std::string write(const TmpDir& dir, const std::string& name, const std::string& text) {
  std::ofstream(dir / name) << text;
  return dir / name;
}

std::string error_of(const std::string& path) {
  try {
    read_camera_file(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Floats parsed from decimal text: exact to float rounding, which EXPECT_FLOAT_EQ (4 ulps) allows.
void expect_pinhole(const Intrinsics& K, float fx, float fy, float cx, float cy) {
  EXPECT_FLOAT_EQ(K.fx, fx);
  EXPECT_FLOAT_EQ(K.fy, fy);
  EXPECT_FLOAT_EQ(K.cx, cx);
  EXPECT_FLOAT_EQ(K.cy, cy);
}

}  // namespace

TEST(CameraFile, OrbSlam2Yaml) {
  TmpDir dir("camfile_orb2");
  // ORB-SLAM2's Examples/RGB-D/TUM1.yaml layout (cv::FileStorage's %YAML:1.0 header).
  const std::string path = write(dir, "TUM1.yaml", R"(%YAML:1.0

#--------------------------------------------------------------------------------------------
# Camera Parameters. Adjust them!
#--------------------------------------------------------------------------------------------

# Camera calibration and distortion parameters (OpenCV)
Camera.fx: 517.306408
Camera.fy: 516.469215
Camera.cx: 318.643040
Camera.cy: 255.313989

Camera.k1: 0.262383
Camera.k2: -0.953104
Camera.p1: -0.005358
Camera.p2: 0.002628
Camera.k3: 1.163314

Camera.width: 640
Camera.height: 480

# Camera frames per second
Camera.fps: 30.0
Camera.bf: 40.0
Camera.RGB: 1
ThDepth: 40.0
DepthMapFactor: 5000.0
ORBextractor.nFeatures: 1000
)");
  const CameraFile c = read_camera_file(path);
  EXPECT_EQ(c.format, "ORB-SLAM YAML");
  expect_pinhole(c.K, 517.306408f, 516.469215f, 318.643040f, 255.313989f);
  const float d[5] = {0.262383f, -0.953104f, -0.005358f, 0.002628f, 1.163314f};
  for (int i = 0; i < 5; ++i) EXPECT_FLOAT_EQ(c.K.dist[i], d[i]) << i;
  EXPECT_TRUE(c.has_size);
  EXPECT_EQ(c.K.width, 640);
  EXPECT_EQ(c.K.height, 480);
}

TEST(CameraFile, OrbSlam3YamlWithoutSizeOrDistortion) {
  TmpDir dir("camfile_orb3");
  const std::string path = write(dir, "cam.yaml",
                                 "%YAML:1.0\nFile.version: \"1.0\"\nCamera.type: \"PinHole\"\n"
                                 "Camera1.fx: 535.4\nCamera1.fy: 539.2\nCamera1.cx: 320.1\nCamera1.cy: 247.6\n");
  const CameraFile c = read_camera_file(path);
  expect_pinhole(c.K, 535.4f, 539.2f, 320.1f, 247.6f);
  for (float d : c.K.dist) EXPECT_EQ(d, 0.f);
  EXPECT_FALSE(c.has_size);
}

TEST(CameraFile, OpenCvFileStorageMatrices) {
  TmpDir dir("camfile_cv");
  // What cv::FileStorage writes for OpenCV's calibration sample (1x5 distortion, type d).
  const std::string path = write(dir, "out_camera_data.yml", R"(%YAML:1.0
---
calibration_time: "Thu 26 Nov 2026 10:00:00 UTC"
image_width: 320
image_height: 240
camera_matrix: !!opencv-matrix
   rows: 3
   cols: 3
   dt: d
   data: [ 2.6e+02, 0., 1.6e+02, 0., 2.55e+02, 1.2e+02, 0., 0., 1. ]
distortion_coefficients: !!opencv-matrix
   rows: 1
   cols: 5
   dt: d
   data: [ 1.0e-01, -2.5e-01, 1.e-03, -2.e-03, 0. ]
)");
  const CameraFile c = read_camera_file(path);
  expect_pinhole(c.K, 260.f, 255.f, 160.f, 120.f);
  EXPECT_FLOAT_EQ(c.K.dist[0], 0.1f);
  EXPECT_FLOAT_EQ(c.K.dist[1], -0.25f);
  EXPECT_FLOAT_EQ(c.K.dist[3], -0.002f);
  EXPECT_EQ(c.K.width, 320);
  EXPECT_EQ(c.K.height, 240);
}

TEST(CameraFile, RosCalibrationAndCameraInfo) {
  TmpDir dir("camfile_ros");
  // camera_calibration_parsers' YAML (what ROS's camera calibrator saves).
  const std::string calib = write(dir, "head_camera.yaml", R"(image_width: 640
image_height: 480
camera_name: head_camera
camera_matrix:
  rows: 3
  cols: 3
  data: [570.3422, 0, 319.5, 0, 570.3422, 239.5, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [0.01, -0.02, 0, 0, 0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [570.3422, 0, 319.5, 0, 0, 570.3422, 239.5, 0, 0, 0, 1, 0]
)");
  CameraFile c = read_camera_file(calib);
  expect_pinhole(c.K, 570.3422f, 570.3422f, 319.5f, 239.5f);
  EXPECT_FLOAT_EQ(c.K.dist[1], -0.02f);
  EXPECT_EQ(c.K.width, 640);
  // sensor_msgs/CameraInfo as `rostopic echo -n1 /camera/rgb/camera_info` prints it.
  const std::string info = write(dir, "camera_info.yaml", R"(header:
  seq: 12
  stamp:
    secs: 1305031102
    nsecs: 175304
  frame_id: "/openni_rgb_optical_frame"
height: 480
width: 640
distortion_model: "plumb_bob"
D: [0.262383, -0.953104, -0.005358, 0.002628, 1.163314]
K: [517.306408, 0.0, 318.643040, 0.0, 516.469215, 255.313989, 0.0, 0.0, 1.0]
R: [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
P: [517.306408, 0.0, 318.643040, 0.0, 0.0, 516.469215, 255.313989, 0.0, 0.0, 0.0, 1.0, 0.0]
binning_x: 0
binning_y: 0
roi:
  x_offset: 0
  y_offset: 0
  height: 0
  width: 0
  do_rectify: False
)");
  c = read_camera_file(info);
  EXPECT_EQ(c.format, "ROS camera_info YAML");
  expect_pinhole(c.K, 517.306408f, 516.469215f, 318.643040f, 255.313989f);
  EXPECT_FLOAT_EQ(c.K.dist[4], 1.163314f);
  EXPECT_EQ(c.K.height, 480);
  // ROS 2 prints the same message with lower-case k and d, and 8 coefficients for
  // rational_polynomial (accepted while k4 k5 k6 are zero).
  const std::string ros2 = write(dir, "ros2.yaml",
                                 "height: 240\nwidth: 320\ndistortion_model: rational_polynomial\n"
                                 "d: [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]\n"
                                 "k: [300.0, 0.0, 160.0, 0.0, 301.0, 120.0, 0.0, 0.0, 1.0]\n");
  c = read_camera_file(ros2);
  expect_pinhole(c.K, 300.f, 301.f, 160.f, 120.f);
  EXPECT_EQ(c.K.width, 320);
}

TEST(CameraFile, Open3dJsonIsColumnMajor) {
  TmpDir dir("camfile_o3d");
  // o3d.io.write_pinhole_camera_intrinsic of PinholeCameraIntrinsic(640, 480, 525, 526, 319.5, 239.5):
  // column-major, so cx and cy are the 7th and 8th numbers.
  const std::string path =
      write(dir, "intrinsic.json",
            "{\n\t\"height\" : 480,\n\t\"intrinsic_matrix\" : \n\t[\n\t\t525.0,\n\t\t0.0,\n\t\t0.0,"
            "\n\t\t0.0,\n\t\t526.0,\n\t\t0.0,\n\t\t319.5,\n\t\t239.5,\n\t\t1.0\n\t],\n\t\"width\" : 640\n}");
  const CameraFile c = read_camera_file(path);
  EXPECT_EQ(c.format, "Open3D JSON");
  expect_pinhole(c.K, 525.f, 526.f, 319.5f, 239.5f);
  EXPECT_EQ(c.K.width, 640);
  EXPECT_EQ(c.K.height, 480);
  // The same numbers read row-major would put cx in the bottom row: refused, not misread.
  const std::string row =
      write(dir, "row.json",
            "{\"width\": 640, \"height\": 480, \"intrinsic_matrix\": [525, 0, 319.5, 0, 526, 239.5, 0, 0, 1]}");
  EXPECT_MENTIONS(error_of(row), "bottom row is not 0 0 1");
}

TEST(CameraFile, ErrorsNameTheFileAndWhatIsMissing) {
  TmpDir dir("camfile_bad");
  std::string p = write(dir, "orb.yaml", "%YAML:1.0\nCamera.fx: 500\nCamera.cx: 320\nCamera.cy: 240\n");
  std::string msg = error_of(p);
  EXPECT_MENTIONS(msg, p);
  EXPECT_MENTIONS(msg, "no Camera.fy");
  p = write(dir, "other.yaml", "fx: 500\nfy: 500\n");
  msg = error_of(p);
  EXPECT_MENTIONS(msg, p);
  EXPECT_MENTIONS(msg, "Camera.fx");
  EXPECT_MENTIONS(msg, "camera_matrix");
  EXPECT_MENTIONS(msg, "intrinsic_matrix");
  p = write(dir, "o3d.json", "{\"width\": 640, \"height\": 480}");
  EXPECT_MENTIONS(error_of(p), "without intrinsic_matrix");
  p = write(dir, "o3d_size.json", "{\"width\": 640, \"intrinsic_matrix\": [525, 0, 0, 0, 525, 0, 319.5, 239.5, 1]}");
  EXPECT_MENTIONS(error_of(p), "has no height");
  p = write(dir, "broken.json", "{\"width\": 640,");
  EXPECT_MENTIONS(error_of(p), "not valid JSON");
  p = write(dir, "cv.yml",
            "%YAML:1.0\ncamera_matrix: !!opencv-matrix\n   rows: 3\n   cols: 3\n   dt: d\n   data: [ 500., 0., 320., "
            "0., 500., 240. ]\n");
  EXPECT_MENTIONS(error_of(p), "camera_matrix says 3x3 but holds 6 numbers");
  p = write(dir, "k4.yaml", "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\nD: [0.1, 0, 0, 0, 0, 0.3, 0, 0]\n");
  EXPECT_MENTIONS(error_of(p), "coefficient 6 is not zero");
  p = write(dir, "fish.yaml",
            "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\ndistortion_model: equidistant\nD: [0.1, 0, 0, 0]\n");
  EXPECT_MENTIONS(error_of(p), "distortion_model is 'equidistant'");
  p = write(dir, "nan.yaml", "K: [500, 0, 320, 0, fivehundred, 240, 0, 0, 1]\n");
  EXPECT_MENTIONS(error_of(p), "K[4] is 'fivehundred', not a number");
  p = write(dir, "zero.yaml", "K: [0, 0, 320, 0, 500, 240, 0, 0, 1]\n");
  EXPECT_MENTIONS(error_of(p), "zero or below one pixel");
  EXPECT_MENTIONS(error_of(dir / "absent.yaml"), "cannot open camera file");
}

TEST(CameraFile, FileAndPresetTogetherIsAConfigError) {
  TmpDir dir("camfile_cfg");
  IntrinsicsParams p;
  p.file = write(dir, "k.yaml", "K: [500, 0, 320, 0, 500, 240, 0, 0, 1]\n");
  IntrinsicsChoice c = choose_intrinsics(p);
  EXPECT_EQ(c.chosen, "k.yaml");
  EXPECT_MENTIONS(c.reason, "ROS camera_info YAML");
  EXPECT_EQ(c.K.width, 640);  // no size in the file: input.intrinsics.width/height
  p.preset = "freiburg1";
  EXPECT_THROW(choose_intrinsics(p), ConfigError);
}

// ICL-NUIM's camera: fx 481.2, fy -480, cx 319.5, cy 239.5 (its image rows run against the camera's
// y axis). Points projected by that camera, read as the flipped image, back-project to themselves.
TEST(CameraFile, NegativeFocalLengthIsAFlippedImageOfTheSameCamera) {
  TmpDir dir("camfile_icl");
  IntrinsicsParams p;
  p.file = write(dir, "icl.yaml", "K: [481.2, 0, 319.5, 0, -480.0, 239.5, 0, 0, 1]\nwidth: 640\nheight: 480\n");
  const IntrinsicsChoice c = choose_intrinsics(p);
  EXPECT_TRUE(c.flip_y);
  EXPECT_FALSE(c.flip_x);
  expect_pinhole(c.K, 481.2f, 480.f, 319.5f, 479.f - 239.5f);
  const double fx = 481.2, fy = -480.0, cx = 319.5, cy = 239.5;
  for (const vec3 P : {vec3{0.3f, 0.2f, 2.f}, vec3{-0.5f, -0.4f, 1.5f}, vec3{0.f, 0.7f, 3.f}}) {
    const double u = fx * P.x / P.z + cx, v = fy * P.y / P.z + cy;                               // the file's camera
    const vec3 back = c.K.unproject(static_cast<float>(u), static_cast<float>(479.0 - v), P.z);  // flipped row
    // float arithmetic on pixel values of a few hundred: about 1e-7 relative, far below 1e-5 m.
    EXPECT_NEAR(back.x, P.x, 1e-5f);
    EXPECT_NEAR(back.y, P.y, 1e-5f);
    // A plain sign-dropped fy (480 without the flip) would put the point on the other side of the axis.
    EXPECT_GT(std::abs(Intrinsics{481.2f, 480.f, 319.5f, 239.5f}.unproject(u, v, P.z).y - P.y), 0.1f * std::abs(P.y));
  }
}

// The same through a frame folder: a wall 2 m away with one marker pixel 1.5 m away where the
// file's camera (negative fy) sees the point P; the frame delivered has the marker where the
// source's intrinsics back-project it to P, colour and depth flipped alike.
TEST(CameraFile, FrameFolderWithNegativeFocalLengthSeesTheSamePoint) {
  TmpDir dir("camfile_icl_frames");
  constexpr int W = 64, H = 48;
  // The file's camera (fy < 0) sees P = (0.2125, 0.3375, 1.5) at pixel (40, 10) exactly:
  // u = 60 * 0.2125 / 1.5 + 31.5 = 40, v = -60 * 0.3375 / 1.5 + 23.5 = 10.
  const int u = 40, v = 10;
  const vec3 P{0.2125f, 0.3375f, 1.5f};
  Image<std::uint16_t> depth(W, H, Device::CPU);
  Image<uchar3> colour(W, H, Device::CPU);
  for (int i = 0; i < W * H; ++i) depth.buffer().data()[i] = 2000, colour.buffer().data()[i] = {90, 90, 90};
  depth.buffer().data()[v * W + u] = 1500;
  colour.buffer().data()[v * W + u] = {255, 0, 0};
  write_png_u16(dir / "frame-000000.depth.png", depth);
  write_png_rgb(dir / "frame-000000.color.png", colour);
  InputParams p;
  p.source = InputSource::frames;
  p.path = dir.str();
  p.check_depth_scale = false;  // a flat wall says nothing about the depth unit
  p.intrinsics.file =
      write(dir, "camera.json",
            "{\"width\": 64, \"height\": 48, \"intrinsic_matrix\": [60, 0, 0, 0, -60, 0, 31.5, 23.5, 1]}");
  FrameFolderSource src(p);
  RgbdFrame f;
  ASSERT_TRUE(src.next(f));
  const std::vector<float> d = f.depth.to_host();
  const std::vector<uchar3> rgb = f.rgb.to_host();
  int found = -1;
  for (int i = 0; i < W * H; ++i)
    if (std::abs(d[i] - 1.5f) < 1e-6f) found = i;
  ASSERT_EQ(found, (H - 1 - v) * W + u);  // the row flipped
  EXPECT_EQ(rgb[found].x, 255);           // colour flipped with it
  EXPECT_EQ(rgb[found].y, 0);
  const vec3 back = src.intrinsics().unproject(static_cast<float>(u), static_cast<float>(H - 1 - v), d[found]);
  EXPECT_NEAR(back.x, P.x, 1e-5f);  // float rounding of pixel values below 100: ~1e-6 m
  EXPECT_NEAR(back.y, P.y, 1e-5f);
  EXPECT_FLOAT_EQ(back.z, P.z);
}
