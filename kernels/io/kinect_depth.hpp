// Kinect v1 raw depth: 11-bit disparity to metres, and registration of the depth (IR camera) image
// to the colour camera. The parameters come from the unit's factory calibration (libfreenect's
// freenect_registration, or the device.json fakenect-record writes); src/io/kinect_model.hpp turns
// them into the KinectDisparityModel below and the per-pixel registration table.
//
// Disparity model (K. Konolige, P. Mihelich, "Technical description of Kinect calibration", ROS wiki
// 2011; the constants as libfreenect's registration.c uses them): the raw value counts 1/8 of a
// pixel of disparity against a reference plane at z0, so inverse depth is linear in it,
//     1/z = 1/z0 + (c + 3/8 - raw/4) / (2 f e)                                              (1)
// with c the unit's const_shift, f = reference_distance / (2 reference_pixel_size) the IR focal
// length in 640-pixel units, e the emitter-to-IR-camera baseline and z0 = 10 reference_distance.
// 2047 is "no reading"; raw values whose (1) is not positive, or beyond max_depth, are no reading too.
//
// Registration: depth pixel (x, y) lands in the colour image at
//     u = table_x(x, y) + f b (1/z0 - 1/z) + 3/8,   v = table_y(x, y)                     (2)
// table_x/y: the unit's lens and rectification polynomial evaluated at (x, y) (built on the host),
// b: the IR-to-colour baseline; the second term is the parallax relative to the reference plane.
// The pixel written is (floor(u), v), the nearest surface wins (z-buffer), as libfreenect does, so
// its registered depth and ours agree except where float and fixed-point rounding cross a pixel border.
#pragma once
#include <cmath>
#include <cstdint>

#include "core/exec.hpp"
#include "core/math.hpp"
#include "core/view.hpp"

namespace seamless::kernels {

inline constexpr std::uint16_t kKinectNoReading = 2047;
// z-buffer value of a colour pixel no depth pixel landed on (depths are stored in micrometres).
inline constexpr std::uint32_t kKinectEmptyDepth = 0xffffffffu;

struct KinectDisparityModel {
  float inv_z0 = 0.f;       // 1 / z0, 1/m
  float inv_2fe = 0.f;      // 1 / (2 f e), 1/m per raw quarter-step (f pixels, e metres)
  float const_shift = 0.f;  // c of (1)
  float fb = 0.f;           // f b, pixel metres: colour-camera parallax of (2)
  float max_depth = 10.f;   // metres; libfreenect's FREENECT_DEPTH_MM_MAX_VALUE
};

// (1): metres, 0 for no reading.
SEAMLESS_HD inline float kinect_raw_to_metres(const KinectDisparityModel& m, std::uint16_t raw) {
  if (raw >= kKinectNoReading) return 0.f;
  const float inv_z = m.inv_z0 + (m.const_shift + 0.375f - 0.25f * static_cast<float>(raw)) * m.inv_2fe;
  if (!(inv_z > 0.f)) return 0.f;
  const float z = 1.f / inv_z;
  return z <= m.max_depth ? z : 0.f;
}

// (2): column shift of a point at depth z (> 0) against the table position, pixels.
SEAMLESS_HD inline float kinect_parallax(const KinectDisparityModel& m, float z) {
  return m.fb * (m.inv_z0 - 1.f / z) + 0.375f;
}

template <Executor Exec> struct KinectDepth {
  // Depth in the IR camera's own view: out(x, y) = (1) of raw(x, y).
  static void raw_to_metres(const Exec& ex, const KinectDisparityModel& m, View2D<const std::uint16_t> raw,
                            View2D<float> out);
  // Depth registered to the colour camera: zbuf is scratch of out's size; table holds (2)'s
  // table_x, table_y per raw pixel (table_x < 0: the pixel maps outside the colour image).
  static void register_to_colour(const Exec& ex, const KinectDisparityModel& m, View2D<const std::uint16_t> raw,
                                 View2D<const vec2> table, View2D<std::uint32_t> zbuf, View2D<float> out);
};

}  // namespace seamless::kernels
