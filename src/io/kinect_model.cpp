#include "io/kinect_model.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.hpp"
#include "core/exec.hpp"
#include "core/exec_cpu.hpp"

namespace seamless {

KinectCalibration kinect_default_calibration() {
  KinectCalibration c;
  c.ax = 1830, c.bx = 11, c.cx = 31, c.dx = 497, c.ay = 56, c.by = 2582, c.cy = 641, c.dy = 77;
  c.dx_start = 3269, c.dy_start = 8447;
  c.dxdx_start = 2096139, c.dxdy_start = 1537, c.dydx_start = 8, c.dydy_start = 2096178;
  c.dxdxdx_start = 134215349, c.dydxdx_start = 134217225, c.dxdxdy_start = 134216993;
  c.dydxdy_start = 134216795, c.dydydx_start = 134217133, c.dydydy_start = 134215132;
  c.emitter_cm = 7.5, c.rgb_cm = 2.4, c.reference_distance = 120, c.reference_pixel_size = 0.1042;
  c.const_shift = 200;
  c.origin = "factory-typical defaults (the OpenISS 2017 recording's unit)";
  return c;
}

KinectCalibration read_kinect_device_json(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw InputError("cannot open the Kinect calibration '" + path + "'");
  std::stringstream text;
  text << f.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(text.str());
  } catch (const nlohmann::json::exception& e) {  // parse_error, and out_of_range for a number overflow
    throw InputError("Kinect calibration '" + path + "' is not valid JSON: " + e.what());
  }
  auto missing = [&](const std::string& key, const char* what) {
    return InputError("Kinect calibration '" + path + "' has no " + what + " '" + key +
                      "' (fakenect-record's device.json: reg_info{...} with zero_plane_info{...}, const_shift)");
  };
  auto object = [&](const nlohmann::json& obj, const char* key, const std::string& where) -> const nlohmann::json& {
    if (!obj.is_object() || !obj.contains(key) || !obj[key].is_object()) throw missing(where + key, "section");
    return obj[key];
  };
  auto number = [&](const nlohmann::json& obj, const char* key, const std::string& where) {
    if (!obj.contains(key) || !obj[key].is_number()) throw missing(where + key, "number");
    const double v = obj[key].get<double>();
    if (!std::isfinite(v) || std::abs(v) > 1e12) throw missing(where + key, "finite number");
    return v;
  };
  const nlohmann::json& r = object(j, "reg_info", "");
  KinectCalibration c;
  // The registration fields are 32-bit registers of the device.
  auto i32 = [&](const char* key) {
    const double v = number(r, key, "reg_info.");
    if (v != std::floor(v) || v < -2147483648.0 || v > 4294967295.0)
      throw missing(std::string("reg_info.") + key, "32-bit integer");
    return static_cast<std::int32_t>(static_cast<std::uint32_t>(static_cast<std::int64_t>(v)));
  };
  c.ax = i32("ax"), c.bx = i32("bx"), c.cx = i32("cx"), c.dx = i32("dx");
  c.ay = i32("ay"), c.by = i32("by"), c.cy = i32("cy"), c.dy = i32("dy");
  c.dx_start = i32("dx_start"), c.dy_start = i32("dy_start");
  c.dxdx_start = i32("dxdx_start"), c.dxdy_start = i32("dxdy_start");
  c.dydx_start = i32("dydx_start"), c.dydy_start = i32("dydy_start");
  c.dxdxdx_start = i32("dxdxdx_start"), c.dydxdx_start = i32("dydxdx_start");
  c.dxdxdy_start = i32("dxdxdy_start"), c.dydxdy_start = i32("dydxdy_start");
  c.dydydx_start = i32("dydydx_start"), c.dydydy_start = i32("dydydy_start");
  if (r.contains("pad_info") && r["pad_info"].is_object() && r["pad_info"].contains("start_lines") &&
      r["pad_info"]["start_lines"].is_number_integer())
    c.pad_start_lines =
        static_cast<int>(std::clamp<std::int64_t>(r["pad_info"]["start_lines"].get<std::int64_t>(), -1000, 1000));
  const nlohmann::json& z = object(r, "zero_plane_info", "reg_info.");
  const std::string zw = "reg_info.zero_plane_info.";
  c.emitter_cm = number(z, "dcmos_emitter_distance", zw);
  c.rgb_cm = number(z, "dcmos_rcmos_distance", zw);
  c.reference_distance = number(z, "reference_distance", zw);
  c.reference_pixel_size = number(z, "reference_pixel_size", zw);
  c.const_shift = number(j, "const_shift", "");
  // Every Kinect v1: 7.5 cm, 2.3-2.4 cm, 120 mm, 0.1042 mm, const_shift about 200.
  if (!(c.emitter_cm > 0.1 && c.emitter_cm < 100 && c.rgb_cm >= 0 && c.rgb_cm < 100 && c.reference_distance > 1 &&
        c.reference_distance < 10000 && c.reference_pixel_size > 1e-3 && c.reference_pixel_size < 10 &&
        std::abs(c.const_shift) < 1e4))
    throw InputError("Kinect calibration '" + path +
                     "': zero_plane_info or const_shift out of any Kinect's range (dcmos_emitter_distance 7.5 cm, "
                     "dcmos_rcmos_distance 2.4 cm, reference_distance 120 mm, reference_pixel_size 0.1042 mm, "
                     "const_shift 200 are typical)");
  c.origin = path;
  return c;
}

kernels::KinectDisparityModel kinect_disparity_model(const KinectCalibration& c, float* ir_focal) {
  // libfreenect's zero-plane numbers in their own units: the reference plane lies at
  // 10 reference_distance millimetres, the IR focal length is reference_distance / (2 pixel size) in
  // 640-pixel units (the 1280-wide sensor is binned by 2), the baselines are in centimetres.
  const double z0 = 0.01 * c.reference_distance;                         // metres
  const double f = c.reference_distance / (2 * c.reference_pixel_size);  // pixels
  const double e = 0.01 * c.emitter_cm, b = 0.01 * c.rgb_cm;             // metres
  kernels::KinectDisparityModel m;
  m.inv_z0 = static_cast<float>(1 / z0);
  m.inv_2fe = static_cast<float>(1 / (2 * f * e));
  m.const_shift = static_cast<float>(c.const_shift);
  m.fb = static_cast<float>(f * b);
  if (ir_focal) *ir_focal = static_cast<float>(f);
  return m;
}

namespace {

// The low `bits` bits of v as a two's-complement number.
std::int64_t signed_field(std::int32_t v, int bits) {
  const std::uint32_t u = static_cast<std::uint32_t>(v) << (32 - bits);
  return static_cast<std::int64_t>(static_cast<std::int32_t>(u) >> (32 - bits));
}

// One coordinate's cubic (x or y) as the forward differences described below: the row-start
// value, its first difference along the row (dcol) and down the rows (drow), the second differences
// (dcol2, dcol_drow, drow2), and the constant third differences a (along the row), b, c, d.
struct CubicAxis {
  std::int64_t start, dcol, drow, dcol2, dcol_drow, drow2;
  std::int32_t a, b, c, d;
  // Advances the row-start terms to the next row.
  void next_row() {
    dcol2 += c;
    dcol += dcol_drow >> 8;
    dcol_drow += d;
    start += drow >> 6;
    drow += drow2 >> 8;
    drow2 += b;
  }
};

// Along one row: the value, its first and second differences, advanced one column by step().
struct RowWalk {
  std::int64_t value, d1, d2;
  void step(std::int32_t third) {
    value += d1 >> 6;
    d1 += d2 >> 8;
    d2 += third;
  }
};

}  // namespace

// The unit stores its rectification as a bivariate cubic per coordinate, evaluated by forward
// differences in fixed point: along a row a value advances by its first difference / 2^6, the
// first difference by the second / 2^8, the second by a constant third (ax, ay); from one row to
// the next the row-start terms advance the same way with their own differences (bx, by, cx, cy,
// dx, dy). The result is in 1/2^17 pixel. The field widths and scalings are the device's
// (19-bit starts x 2^9, 21-bit first differences x 2^8, 24-bit second differences x 2^8).
std::vector<vec2> kinect_registration_table(const KinectCalibration& c) {
  const int W = kKinectWidth, H = kKinectHeight;
  // Row-start state: offsets, their column differences, and those differences' row differences.
  const std::int64_t x0 = signed_field(c.dx_start, 19) << 9, y0 = signed_field(c.dy_start, 19) << 9;
  const std::int64_t x_dcol = signed_field(c.dxdx_start, 21) << 8, y_dcol = signed_field(c.dxdy_start, 21) << 8;
  const std::int64_t x_drow = signed_field(c.dydx_start, 21) << 8, y_drow = signed_field(c.dydy_start, 21) << 8;
  const std::int64_t x_dcol2 = signed_field(c.dxdxdx_start, 24) << 8, y_dcol2 = signed_field(c.dxdxdy_start, 24) << 8;
  const std::int64_t x_dr_dc = signed_field(c.dydxdx_start, 24) << 8, y_dr_dc = signed_field(c.dydxdy_start, 24) << 8;
  const std::int64_t x_drow2 = signed_field(c.dydydx_start, 24) << 8, y_drow2 = signed_field(c.dydydy_start, 24) << 8;
  CubicAxis x{x0, x_dcol, x_drow, x_dcol2, x_dr_dc, x_drow2, c.ax, c.bx, c.cx, c.dx};
  CubicAxis y{y0, y_dcol, y_drow, y_dcol2, y_dr_dc, y_drow2, c.ay, c.by, c.cy, c.dy};
  std::vector<vec2> table(static_cast<std::size_t>(W) * H);
  const double unit = 1.0 / (1 << 17);
  for (int row = 0; row < H; ++row) {
    x.next_row();  // the device steps before its first row as well
    y.next_row();
    RowWalk xr{x.start, x.dcol, x.dcol2}, yr{y.start, y.dcol, y.dcol2};
    for (int col = 0; col < W; ++col) {
      // The device's pixel centres are one pixel down and right of ours.
      const double u = col + xr.value * unit + 1, v = row + yr.value * unit + 1;
      const bool inside = u >= 0 && v >= 0 && u < W && v < H;
      table[static_cast<std::size_t>(row) * W + col] = {inside ? static_cast<float>(u) : -1.f,
                                                        static_cast<float>(std::floor(v))};
      xr.step(x.a);
      yr.step(y.a);
    }
  }
  return table;
}

KinectRegistrar::KinectRegistrar(const KinectCalibration& c)
    : model_(kinect_disparity_model(c)),
      table_(Image<vec2>::from_host(kinect_registration_table(c), kKinectWidth, kKinectHeight, Device::CPU)),
      raw_(kKinectWidth, kKinectHeight, Device::CPU), zbuf_(kKinectWidth, kKinectHeight, Device::CPU) {
  if (c.pad_start_lines != 0)
    spdlog::warn("Kinect calibration ({}): pad_info.start_lines {} is not applied (0 on every unit seen)", c.origin,
                 c.pad_start_lines);
}

void KinectRegistrar::register_depth(const std::uint16_t* raw, Image<float>& out) {
  raw_.buffer().copy_from_host(raw, raw_.buffer().size());
  CpuExec ex;
  kernels::KinectDepth<CpuExec>::register_to_colour(ex, model_, raw_.cview(), table_.cview(), zbuf_.view(), out.view());
}

vec3 kinect_accel_to_camera(std::int16_t ax, std::int16_t ay, std::int16_t az) {
  const float s = 9.80665f / 819.f;
  return {-ax * s, -ay * s, az * s};
}

bool kinect_next_colour_is_nearer(std::uint32_t depth, std::uint32_t before, std::uint32_t after) {
  // Unsigned differences wrap with the clock; the distances are far below 2^31 ticks (36 s).
  const auto dist = [](std::uint32_t a, std::uint32_t b) {
    const std::int32_t d = static_cast<std::int32_t>(a - b);
    return d < 0 ? -static_cast<std::int64_t>(d) : static_cast<std::int64_t>(d);
  };
  return dist(after, depth) < dist(depth, before);
}

}  // namespace seamless
