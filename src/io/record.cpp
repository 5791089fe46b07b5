#include "io/record.hpp"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/error.hpp"
#include "core/interrupt.hpp"
#include "io/intrinsics_presets.hpp"
#include "io/movers.hpp"
#include "io/png_io.hpp"
#include "io/trajectory.hpp"

namespace seamless {
namespace fs = std::filesystem;
namespace {

std::ofstream open_list(const fs::path& p, const std::string& header) {
  std::ofstream f(p);
  if (!f) throw Error("cannot create '" + p.string() + "': " + std::strerror(errno));
  f << header << std::flush;
  return f;
}

std::string stamp(double t) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.6f", t);
  return buf;
}

Image<std::uint16_t> to_u16(const Image<float>& depth, double scale) {
  Image<std::uint16_t> out(depth.width(), depth.height(), Device::CPU);
  const float* d = depth.buffer().data();
  std::uint16_t* o = out.buffer().data();
  for (std::int64_t i = 0; i < depth.buffer().size(); ++i) {
    double v = std::round(d[i] * scale);
    o[i] = (d[i] > 0.f && v <= 65535.0) ? static_cast<std::uint16_t>(v) : 0;
  }
  return out;
}

}  // namespace

std::int64_t record(FrameSource& source, const std::string& out_dir, const RecordOptions& opt) {
  fs::path dir(out_dir);
  std::error_code ec;
  fs::create_directories(dir / "rgb", ec);
  fs::create_directories(dir / "depth", ec);
  if (ec) throw Error("cannot create recording folder '" + out_dir + "': " + ec.message());
  std::string origin = "# recorded by seamless from " + source.name() + "\n";
  std::ofstream rgb_txt = open_list(dir / "rgb.txt", "# color images\n" + origin + "# timestamp filename\n");
  std::ofstream depth_txt = open_list(dir / "depth.txt", "# depth maps\n" + origin + "# timestamp filename\n");
  std::ofstream assoc_txt = open_list(dir / "associations.txt", "");
  std::ofstream accel_txt, movers_txt;
  std::unique_ptr<TrajectoryWriter> gt;
  write_calibration((dir / "calibration.txt").string(), source.intrinsics());
  RgbdFrame f;
  std::int64_t n = 0;
  // Ctrl-C (or SIGTERM) ends the recording after the frame being written.
  while ((opt.max_frames <= 0 || n < opt.max_frames) && !interrupted() && source.next(f)) {
    std::string name = stamp(f.timestamp) + ".png";
    write_png_rgb((dir / "rgb" / name).string(), f.rgb);
    write_png_u16((dir / "depth" / name).string(), to_u16(f.depth, opt.depth_scale));
    if (f.mover_mask.width() > 0) {  // the movers' ground truth: masks first, then their list line
      if (!movers_txt.is_open()) fs::create_directories(dir / "mask", ec);  // with the list, once
      write_png_u8((dir / "mask" / name).string(), f.mover_mask);
      if (!movers_txt.is_open())
        movers_txt =
            open_list(dir / "movers.txt", "# movers (capsules) of the synthetic room, frame of groundtruth.txt\n" +
                                              origin + "# timestamp mover ax ay az bx by bz radius\n");
      if (f.movers) movers_txt << movers_lines(f.timestamp, *f.movers) << std::flush;
    }
    // The lists name a frame only once both its images are written, and reach the disk with every
    // frame: a recording that is killed is a folder that loads, up to its last whole frame.
    rgb_txt << stamp(f.timestamp) << " rgb/" << name << '\n' << std::flush;
    depth_txt << stamp(f.timestamp) << " depth/" << name << '\n' << std::flush;
    assoc_txt << stamp(f.timestamp) << " rgb/" << name << ' ' << stamp(f.timestamp) << " depth/" << name << '\n'
              << std::flush;
    if (f.accelerometer) {
      if (!accel_txt.is_open())
        accel_txt = open_list(dir / "accelerometer.txt", "# accelerometer data\n" + origin + "# timestamp ax ay az\n");
      // Back to the Kinect's own axes (x left, y up), as TUM stores them; see tum_source.cpp.
      vec3 a = *f.accelerometer;
      accel_txt << stamp(f.timestamp) << ' ' << -a.x << ' ' << -a.y << ' ' << a.z << '\n' << std::flush;
    }
    if (f.ground_truth) {
      if (!gt) gt = std::make_unique<TrajectoryWriter>((dir / "groundtruth.txt").string(), "ground truth trajectory");
      gt->write(f.timestamp, *f.ground_truth);
    }
    ++n;
  }
  for (std::ofstream* s : {&rgb_txt, &depth_txt, &assoc_txt, &accel_txt, &movers_txt})
    if (s->is_open() && !s->flush()) throw Error("cannot write the lists of recording '" + out_dir + "'");
  if (gt) gt->close();
  return n;
}

}  // namespace seamless
