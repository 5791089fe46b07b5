// The fakenect recording format, as Debian's libfreenect 0.5 replays it: FAKENECT_PATH/INDEX.txt
// lists one file a line, `<type>-<seconds>-<device timestamp>-<anything>`; each file's payload is
// handed to the application unchanged (after the one-line PGM/PPM header for images), and 'a'
// files are a raw freenect_raw_tilt_state. Replay pauses between lines as the seconds say. Each frame
// is written colour, depth, accelerometer, the order fakenect-record writes them in (a depth frame
// takes the accelerometer state received before the next colour frame: kinect_source.hpp).
#include <libfreenect.h>

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "io/kinect_source.hpp"

namespace seamless {
namespace {

void write_file(const std::filesystem::path& p, const std::string& header, const void* data, std::size_t bytes) {
  std::ofstream f(p, std::ios::binary);
  f << header;
  f.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  if (!f) throw Error("cannot write fakenect file '" + p.string() + "': " + std::strerror(errno));
}

std::int16_t counts(float mps2) {
  return static_cast<std::int16_t>(std::lround(mps2 / 9.80665 * FREENECT_COUNTS_PER_G));
}

}  // namespace

std::int64_t write_fakenect_dump(FrameSource& source, const std::string& dir, std::int64_t max_frames) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw Error("cannot create fakenect folder '" + dir + "': " + ec.message());
  std::ofstream index(fs::path(dir) / "INDEX.txt");
  RgbdFrame f;
  std::int64_t n = 0;
  while ((max_frames <= 0 || n < max_frames) && source.next(f)) {
    if (f.depth.width() != 640 || f.depth.height() != 480)
      throw Error("fakenect replays 640x480 only; source '" + source.name() + "' gives " +
                  std::to_string(f.depth.width()) + "x" + std::to_string(f.depth.height()));
    char stem[96];
    std::snprintf(stem, sizeof stem, "%.6f-%lld", f.timestamp, static_cast<long long>(n));
    // Accelerometer: back from camera axes to the Kinect's (x left, y up), in raw counts.
    freenect_raw_tilt_state tilt{};
    if (f.accelerometer) {
      tilt.accelerometer_x = counts(-f.accelerometer->x);
      tilt.accelerometer_y = counts(-f.accelerometer->y);
      tilt.accelerometer_z = counts(f.accelerometer->z);
    }
    std::string a = std::string("a-") + stem + "-.dump", r = std::string("r-") + stem + "-.ppm",
                d = std::string("d-") + stem + "-.pgm";
    write_file(fs::path(dir) / a, "", &tilt, sizeof tilt);
    write_file(fs::path(dir) / r, "P6 640 480 255\n", f.rgb.buffer().data(), f.rgb.buffer().bytes());
    std::vector<std::uint16_t> mm(f.depth.buffer().size());
    const float* z = f.depth.buffer().data();
    for (std::size_t i = 0; i < mm.size(); ++i) {
      long v = std::lround(z[i] * 1000.0);
      mm[i] = (z[i] > 0.f && v <= FREENECT_DEPTH_MM_MAX_VALUE) ? static_cast<std::uint16_t>(v) : 0;
    }
    write_file(fs::path(dir) / d, "P5 640 480 65535\n", mm.data(), mm.size() * 2);
    index << r << '\n' << d << '\n' << a << '\n';
    ++n;
  }
  if (!index.flush()) throw Error("cannot write '" + dir + "/INDEX.txt'");
  return n;
}

}  // namespace seamless
