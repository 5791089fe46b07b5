// A fakenect-record folder read directly, without libfreenect (input.source: fakenect, or any
// input.path holding such a folder's INDEX.txt): the format every libfreenect recording of a
// Kinect v1 has, replayed through the same depth model and registration as a live Kinect in raw
// mode (io/kinect_model.hpp), so it also serves machines without libfreenect and fast tests.
//
// The folder: INDEX.txt lists one record a line, `<type>-<seconds>-<device ticks>.<ext>` in the
// order they arrived: d-*.pgm raw 11-bit disparity ("P5 640 480 65535", 16-bit samples in either
// byte order, 2047 = no reading), r-*.ppm colour ("P6 640 480 255"), a-*.dump the accelerometer
// (freenect_raw_tilt_state, 12 bytes little-endian), and device.json the unit's registration.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "io/frame_source.hpp"
#include "io/input_params.hpp"
#include "io/kinect_model.hpp"

namespace seamless {

struct FakenectRecord {
  char type = 0;            // 'd' depth, 'r' colour, 'a' accelerometer
  double seconds = 0.0;     // host clock when it arrived
  std::uint32_t ticks = 0;  // device clock (60 MHz)
  std::string file;         // name in the folder
};

// INDEX.txt's records. Throws InputError naming INDEX.txt and the line that does not parse.
std::vector<FakenectRecord> read_fakenect_index(const std::string& dir);
// True when `dir` holds an INDEX.txt (what fakenect itself looks for).
bool is_fakenect_folder(const std::string& dir);

enum class SampleOrder { little_endian, big_endian };
const char* sample_order_name(SampleOrder o);
// The byte order of raw 11-bit samples, told by the values: the one in which every sample fits in
// 11 bits (the other order puts the low byte on top: values far beyond 2047). Both (a frame of
// tiny values only): big-endian, the PGM standard. Neither: InputError naming `file` (not raw disparity).
SampleOrder kinect_sample_order(const std::uint8_t* bytes, std::size_t samples, const std::string& file);

// A depth record: 640x480 raw disparity in host order. `order`: found on the first call and kept
// (a later frame in the other order is an error). Throws InputError naming the file when it is
// missing, not a 16-bit 640x480 PGM, or truncated.
std::vector<std::uint16_t> read_kinect_raw_pgm(const std::string& file, std::optional<SampleOrder>& order);

class FakenectSource : public FrameSource {
 public:
  explicit FakenectSource(const InputParams& params, bool pinned = false);
  bool next(RgbdFrame& frame) override;
  std::optional<std::int64_t> size() const override { return static_cast<std::int64_t>(frames_.size()); }
  std::string name() const override { return "fakenect:" + dir_; }
  Intrinsics intrinsics() const override { return K_; }
  std::int64_t skipped_frames() const override { return skipped_; }

 private:
  struct Frame {
    std::size_t depth;  // record indices into records_
    std::optional<std::size_t> colour, accel;
  };
  bool read(const Frame& f, RgbdFrame& frame);

  InputParams params_;
  bool pinned_ = false;
  std::string dir_;
  Intrinsics K_;
  std::vector<FakenectRecord> records_;
  std::vector<Frame> frames_;
  std::optional<KinectRegistrar> registrar_;
  std::optional<SampleOrder> order_;
  std::vector<std::uint8_t> rgb_scratch_;
  std::size_t pos_ = 0;
  std::int64_t delivered_ = 0, skipped_ = 0;
};

// The calibration for a recording folder or a replay: `explicit_path` (input.kinect.calibration)
// when given, else `<dir>/device.json` when present, else the defaults (with a warning).
KinectCalibration kinect_calibration_for(const std::string& explicit_path, const std::string& dir);

}  // namespace seamless
