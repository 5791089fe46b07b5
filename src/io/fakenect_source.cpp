#include "io/fakenect_source.hpp"

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/error.hpp"
#include "io/intrinsics_presets.hpp"

namespace seamless {
namespace fs = std::filesystem;

std::vector<FakenectRecord> read_fakenect_index(const std::string& dir) {
  const std::string index = (fs::path(dir) / "INDEX.txt").string();
  std::ifstream in(index);
  if (!in)
    throw InputError("'" + dir +
                     "' has no INDEX.txt: not a fakenect-record folder (a TUM folder has rgb.txt and depth.txt: "
                     "input.source: tum; a frame folder frame-NNNNNN files: input.source: frames)");
  std::vector<FakenectRecord> records;
  int line_no = 0;
  for (std::string line; std::getline(in, line);) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    FakenectRecord r;
    unsigned ticks = 0;
    // fakenect's own reading of a line: type, seconds, device ticks (the rest is free).
    if (std::sscanf(line.c_str(), "%c-%lf-%u", &r.type, &r.seconds, &ticks) != 3 ||
        (r.type != 'd' && r.type != 'r' && r.type != 'a'))
      throw InputError(index + " line " + std::to_string(line_no) + " '" + line +
                       "' is not a fakenect record (d-, r- or a-<seconds>-<ticks>...)");
    r.ticks = ticks;
    r.file = line;
    records.push_back(std::move(r));
  }
  return records;
}

bool is_fakenect_folder(const std::string& dir) {
  std::error_code ec;
  return !dir.empty() && fs::is_regular_file(fs::path(dir) / "INDEX.txt", ec);
}

const char* sample_order_name(SampleOrder o) {
  return o == SampleOrder::little_endian ? "little-endian" : "big-endian";
}

SampleOrder kinect_sample_order(const std::uint8_t* bytes, std::size_t samples, const std::string& file) {
  std::uint16_t max_le = 0, max_be = 0;
  for (std::size_t i = 0; i < samples; ++i) {
    const std::uint16_t lo = bytes[2 * i], hi = bytes[2 * i + 1];
    max_le = std::max<std::uint16_t>(max_le, static_cast<std::uint16_t>(lo | hi << 8));
    max_be = std::max<std::uint16_t>(max_be, static_cast<std::uint16_t>(hi | lo << 8));
  }
  const bool le = max_le <= kernels::kKinectNoReading, be = max_be <= kernels::kKinectNoReading;
  if (be) return SampleOrder::big_endian;
  if (le) return SampleOrder::little_endian;
  throw InputError("depth image '" + file + "' is not raw 11-bit Kinect disparity: its samples reach " +
                   std::to_string(max_be) + " read big-endian and " + std::to_string(max_le) +
                   " little-endian, both beyond 2047 (registered millimetres, as write_fakenect_dump "
                   "records, replay through fakenect with input.source: kinect)");
}

namespace {

// Reads a binary PNM (P5/P6) header: magic, width, height, maxval, each after whitespace or '#'
// comments, then exactly one whitespace byte. Returns the offset of the samples.
std::size_t pnm_header(const std::vector<std::uint8_t>& b, const std::string& file, const char* magic, int& w, int& h,
                       int& maxval) {
  std::size_t p = 0;
  auto token = [&]() -> std::string {
    while (p < b.size() && (std::isspace(b[p]) || b[p] == '#')) {
      if (b[p] == '#')
        while (p < b.size() && b[p] != '\n') ++p;
      else ++p;
    }
    std::string t;
    while (p < b.size() && !std::isspace(b[p]) && t.size() < 16) t += static_cast<char>(b[p++]);
    return t;
  };
  const std::string m = token();
  if (m != magic) throw InputError("'" + file + "' is not a binary " + magic + " image (starts with '" + m + "')");
  try {
    w = std::stoi(token());
    h = std::stoi(token());
    maxval = std::stoi(token());
  } catch (const std::exception&) {
    throw InputError("'" + file + "': unreadable " + magic + " header");
  }
  if (p >= b.size()) throw InputError("'" + file + "': the " + std::string(magic) + " header has no image after it");
  return p + 1;  // the single whitespace byte after maxval
}

std::vector<std::uint8_t> read_bytes(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError("cannot open '" + file + "' (listed in INDEX.txt)");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void check_size(const std::string& file, int w, int h, const char* what) {
  if (w != kKinectWidth || h != kKinectHeight)
    throw InputError("'" + file + "' is " + std::to_string(w) + "x" + std::to_string(h) + " " + what +
                     "; a Kinect v1 recording has 640x480");
}

void check_payload(const std::string& file, std::size_t have, std::size_t need) {
  if (have < need)
    throw InputError("'" + file + "' is truncated: " + std::to_string(need) + " bytes of samples expected, " +
                     std::to_string(have) + " found");
}

}  // namespace

std::vector<std::uint16_t> read_kinect_raw_pgm(const std::string& file, std::optional<SampleOrder>& order) {
  const std::vector<std::uint8_t> b = read_bytes(file);
  int w = 0, h = 0, maxval = 0;
  const std::size_t off = pnm_header(b, file, "P5", w, h, maxval);
  check_size(file, w, h, "depth");
  if (maxval < 256)
    throw InputError("'" + file + "' has 8-bit samples (maxval " + std::to_string(maxval) +
                     "); raw Kinect depth is 16-bit");
  const std::size_t n = static_cast<std::size_t>(w) * h;
  check_payload(file, b.size() - off, 2 * n);
  const std::uint8_t* s = b.data() + off;
  const SampleOrder found = kinect_sample_order(s, n, file);
  if (!order) {
    order = found;
    spdlog::info("raw Kinect depth: 16-bit samples stored {} ('{}'{})", sample_order_name(found), file,
                 found == SampleOrder::little_endian ? ", under a PGM header that nominally means big-endian" : "");
  } else if (*order != found) {
    throw InputError("depth image '" + file + "' has its samples " + sample_order_name(found) +
                     " while the recording's first frame had them " + sample_order_name(*order));
  }
  std::vector<std::uint16_t> raw(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint16_t a = s[2 * i], c = s[2 * i + 1];
    raw[i] = found == SampleOrder::little_endian ? static_cast<std::uint16_t>(a | c << 8)
                                                 : static_cast<std::uint16_t>(c | a << 8);
  }
  return raw;
}

KinectCalibration kinect_calibration_for(const std::string& explicit_path, const std::string& dir) {
  if (!explicit_path.empty()) return read_kinect_device_json(explicit_path);
  std::error_code ec;
  const fs::path json = fs::path(dir) / "device.json";
  if (!dir.empty() && fs::is_regular_file(json, ec)) return read_kinect_device_json(json.string());
  KinectCalibration c = kinect_default_calibration();
  spdlog::warn(
      "Kinect: no device.json{} and no input.kinect.calibration: using {}; registration to colour may be off by "
      "a few pixels for this unit",
      dir.empty() ? "" : " in '" + dir + "'", c.origin);
  return c;
}

FakenectSource::FakenectSource(const InputParams& params, bool pinned)
    : params_(params), pinned_(pinned), dir_(params.path) {
  records_ = read_fakenect_index(dir_);
  K_ = resolve_intrinsics(params.intrinsics).K;
  if (K_.width != kKinectWidth || K_.height != kKinectHeight)
    throw ConfigError("input.intrinsics width/height must be 640x480 for a Kinect v1 recording");
  std::size_t n_colour = 0, n_accel = 0;
  for (const auto& r : records_) n_colour += r.type == 'r', n_accel += r.type == 'a';
  // Each depth record takes the colour record nearest in device time among the last one before it
  // and the first one after it (before the next depth record), and the accelerometer state
  // received before that choice is made: what a live Kinect in raw mode does (kinect_source.cpp).
  std::optional<std::size_t> last_colour, last_accel;
  std::int64_t no_colour = 0;
  for (std::size_t i = 0; i < records_.size(); ++i) {
    const char t = records_[i].type;
    if (t == 'r') last_colour = i;
    if (t == 'a') last_accel = i;
    if (t != 'd') continue;
    std::size_t j = i + 1;
    std::optional<std::size_t> accel = last_accel;
    while (j < records_.size() && records_[j].type == 'a') accel = j++;
    std::optional<std::size_t> after;
    if (j < records_.size() && records_[j].type == 'r') after = j;
    Frame f{i, last_colour, accel};
    if (after && (!last_colour || kinect_next_colour_is_nearer(records_[i].ticks, records_[*last_colour].ticks,
                                                               records_[*after].ticks)))
      f.colour = after;
    if (!f.colour && n_colour > 0) {
      ++no_colour;  // a live Kinect drops such a frame too
      continue;
    }
    frames_.push_back(f);
  }
  if (frames_.empty())
    throw InputError("'" + dir_ + "/INDEX.txt' lists no depth record (d-*.pgm) with a colour record next to it");
  if (no_colour > 0)
    spdlog::info("fakenect folder '{}': {} depth records before any colour record left out", dir_, no_colour);
  if (n_colour == 0)
    spdlog::warn("fakenect folder '{}' has no colour records (r-*.ppm): the frames get a uniform grey colour image",
                 dir_);
  if (n_accel == 0)
    spdlog::warn(
        "fakenect folder '{}' has no accelerometer records (a-*.dump): frames carry no gravity "
        "(tracker.gravity: auto finds it from the scene)",
        dir_);
  const auto first =
      static_cast<std::size_t>(std::min<std::int64_t>(params.first_frame, static_cast<std::int64_t>(frames_.size())));
  frames_.erase(frames_.begin(), frames_.begin() + static_cast<std::ptrdiff_t>(first));
  if (params.max_frames > 0 && static_cast<std::int64_t>(frames_.size()) > params.max_frames)
    frames_.resize(static_cast<std::size_t>(params.max_frames));
  const KinectCalibration cal = kinect_calibration_for(params.kinect.calibration, dir_);
  registrar_.emplace(cal);
  spdlog::info("fakenect folder '{}': {} frames, Kinect calibration from {}", dir_, frames_.size(), cal.origin);
}

bool FakenectSource::read(const Frame& f, RgbdFrame& frame) {
  const FakenectRecord& d = records_[f.depth];
  const std::string depth_file = (fs::path(dir_) / d.file).string();
  const std::vector<std::uint16_t> raw = read_kinect_raw_pgm(depth_file, order_);
  reserve_frame_images(frame, kKinectWidth, kKinectHeight, pinned_);
  registrar_->register_depth(raw.data(), frame.depth);
  uchar3* rgb = frame.rgb.buffer().data();
  const std::size_t n = static_cast<std::size_t>(kKinectWidth) * kKinectHeight;
  if (f.colour) {
    const std::string file = (fs::path(dir_) / records_[*f.colour].file).string();
    rgb_scratch_ = read_bytes(file);
    int w = 0, h = 0, maxval = 0;
    const std::size_t off = pnm_header(rgb_scratch_, file, "P6", w, h, maxval);
    check_size(file, w, h, "colour");
    if (maxval != 255)
      throw InputError("'" + file + "' has maxval " + std::to_string(maxval) + "; Kinect colour is 8-bit (255)");
    check_payload(file, rgb_scratch_.size() - off, 3 * n);
    std::memcpy(rgb, rgb_scratch_.data() + off, 3 * n);
  } else {
    for (std::size_t i = 0; i < n; ++i) rgb[i] = {128, 128, 128};
  }
  frame.accelerometer.reset();
  if (f.accel) {
    const std::string file = (fs::path(dir_) / records_[*f.accel].file).string();
    const std::vector<std::uint8_t> a = read_bytes(file);
    // freenect_raw_tilt_state: int16 x, y, z little-endian, then the tilt angle and status.
    if (a.size() < 6)
      throw InputError("accelerometer record '" + file + "' has " + std::to_string(a.size()) +
                       " bytes; freenect_raw_tilt_state has 12");
    auto s16 = [&](int k) { return static_cast<std::int16_t>(a[2 * k] | a[2 * k + 1] << 8); };
    // All zero: fakenect-record saved the state before the first reading (a live Kinect's too).
    if (s16(0) || s16(1) || s16(2)) frame.accelerometer = kinect_accel_to_camera(s16(0), s16(1), s16(2));
  }
  frame.index = delivered_;
  frame.timestamp = d.seconds;
  frame.intrinsics = K_;
  frame.ground_truth.reset();
  return true;
}

bool FakenectSource::next(RgbdFrame& frame) {
  while (pos_ < frames_.size()) {
    const Frame& f = frames_[pos_++];
    try {
      read(f, frame);
      ++delivered_;
      return true;
    } catch (const InputError& e) {
      if (!params_.skip_bad_frames) throw;
      spdlog::warn("skipping frame: {}", e.what());
      ++skipped_;
    }
  }
  return false;
}

}  // namespace seamless
