// The Kinect v1's depth model on the host: the unit's calibration (as libfreenect's
// freenect_registration holds it, or as fakenect-record saves it in device.json), factory-typical
// defaults, and what the per-pixel kernels of kernels/io/kinect_depth.hpp need from it: the
// disparity model and the registration table. Also the small conventions every Kinect v1 source
// shares: accelerometer counts to the camera frame, and which colour frame goes with a depth frame.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "core/buffer.hpp"
#include "core/math.hpp"
#include "kernels/io/kinect_depth.hpp"

namespace seamless {

inline constexpr int kKinectWidth = 640, kKinectHeight = 480;

// The unit's factory calibration, field by field as the device reports it (libfreenect's
// freenect_reg_info, freenect_reg_pad_info, freenect_zero_plane_info and const_shift).
struct KinectCalibration {
  // Registration polynomial, fixed point (registration_table() says how each field is scaled).
  std::int32_t ax = 0, bx = 0, cx = 0, dx = 0, ay = 0, by = 0, cy = 0, dy = 0;
  std::int32_t dx_start = 0, dy_start = 0;
  std::int32_t dxdx_start = 0, dxdy_start = 0, dydx_start = 0, dydy_start = 0;
  std::int32_t dxdxdx_start = 0, dydxdx_start = 0, dxdxdy_start = 0, dydxdy_start = 0, dydydx_start = 0,
               dydydy_start = 0;
  int pad_start_lines = 0;  // rows cropped at the top of the sensor image (0 on every unit seen)
  // Zero plane: IR camera to emitter and to colour camera (cm), reference distance and pixel size (mm).
  double emitter_cm = 0, rgb_cm = 0, reference_distance = 0, reference_pixel_size = 0;
  double const_shift = 0;
  std::string origin;  // where the values came from, for the log
};

// The factory calibration of one production unit, saved by fakenect-record with a public recording
// (OpenISS, 2017, Apache-2.0: the device.json of its test-recording), the only complete one
// published with its recording. Units differ: libfreenect 0.1's built-in unit, applied to that
// recording, puts depth edges 18 px from their colour edges (docs/INPUT.md), so a unit's own values
// are always preferred.
KinectCalibration kinect_default_calibration();

// device.json as fakenect-record writes it (keys reg_info{...}, reg_info.zero_plane_info{...},
// const_shift). Throws InputError naming the file and the missing or malformed key.
KinectCalibration read_kinect_device_json(const std::string& path);

// (1) of kernels/io/kinect_depth.hpp from the calibration; IR focal length in `ir_focal`.
kernels::KinectDisparityModel kinect_disparity_model(const KinectCalibration& c, float* ir_focal = nullptr);

// (2)'s table: for each raw pixel (row-major 640 x 480) its colour-image position before parallax;
// x < 0 where the polynomial sends it outside the image.
std::vector<vec2> kinect_registration_table(const KinectCalibration& c);

// Turns raw 640x480 disparity frames into depth registered to the colour camera, on the host
// (OpenMP): the model and table are made once per calibration.
class KinectRegistrar {
 public:
  explicit KinectRegistrar(const KinectCalibration& c);
  // raw: 640*480 samples; out: a 640x480 host image (metres, 0 = no reading).
  void register_depth(const std::uint16_t* raw, Image<float>& out);
  const kernels::KinectDisparityModel& model() const { return model_; }

 private:
  kernels::KinectDisparityModel model_;
  Image<vec2> table_;
  Image<std::uint16_t> raw_;
  Image<std::uint32_t> zbuf_;
};

// Specific force in the camera frame (x right, y down, z forward; m/s^2, up at rest) from the
// accelerometer's counts (freenect_raw_tilt_state; 819 counts = 1 g). Gravity points along
// (ax, ay, -az) in the camera frame, so the specific force is -(ax, ay, -az) g / 819.
vec3 kinect_accel_to_camera(std::int16_t ax, std::int16_t ay, std::int16_t az);

// Colour frame for a depth frame, given the device clocks (60 MHz ticks, wrapping at 2^32) of the
// last colour frame before it and of the first after it (before the next depth frame): true when
// the later one is nearer in time (a tie goes to the earlier).
bool kinect_next_colour_is_nearer(std::uint32_t depth, std::uint32_t before, std::uint32_t after);

}  // namespace seamless
