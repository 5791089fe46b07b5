// Per-stage timings. On the CPU a steady clock; on CUDA events recorded around the stage, read back
// once per frame (end_frame) so that timing does not serialise the pipeline.
#pragma once
#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "core/device.hpp"

namespace seamless {

class StageTimer {
 public:
  explicit StageTimer(Device d);
  ~StageTimer();
  StageTimer(const StageTimer&) = delete;
  StageTimer& operator=(const StageTimer&) = delete;

  void begin(const std::string& stage);
  void end(const std::string& stage);
  // Resolves this frame's stages into milliseconds and appends one row per stage.
  void end_frame(std::int64_t frame);

  struct Row {
    std::int64_t frame;
    std::string stage;
    double ms;
  };
  // Appends a stage time measured elsewhere (e.g. by a layer's own timer).
  void add(std::int64_t frame, const std::string& stage, double ms) { rows_.push_back({frame, stage, ms}); }
  const std::vector<Row>& rows() const { return rows_; }
  void write_csv(const std::string& path) const;  // frame,stage,ms
  // Median ms of a stage over all frames (0 if none).
  double median_ms(const std::string& stage) const;

 private:
  struct Pending;
  Device device_;
  std::vector<Pending*> pending_;
  std::vector<Row> rows_;
};

// RAII helper: StageScope s(timer, "integrate");
class StageScope {
 public:
  StageScope(StageTimer& t, std::string stage) : t_(t), stage_(std::move(stage)) { t_.begin(stage_); }
  ~StageScope() { t_.end(stage_); }
  StageScope(const StageScope&) = delete;
  StageScope& operator=(const StageScope&) = delete;

 private:
  StageTimer& t_;
  std::string stage_;
};

double median(std::vector<double> v);

// Points on the device's timeline, for a pipeline that times its stages without waiting for each:
// mark(k) records CUDA event k on the legacy default stream (the host clock on the CPU), and
// ms(a, b) waits for mark b and returns the time between marks a and b. The events are made once.
class DeviceMarks {
 public:
  DeviceMarks(Device d, int count);
  ~DeviceMarks();
  DeviceMarks(const DeviceMarks&) = delete;
  DeviceMarks& operator=(const DeviceMarks&) = delete;
  void mark(int k);
  double ms(int a, int b) const;

 private:
  Device device_;
  std::vector<std::chrono::steady_clock::time_point> host_;
  std::vector<void*> events_;  // cudaEvent_t
};

}  // namespace seamless

namespace seamless {
// Time of one call of fn in milliseconds: CUDA events around it on the GPU, a steady clock on the
// CPU (after synchronising), so device work is counted and host launch overhead alone is not.
double measure_ms(Device d, const std::function<void()>& fn);
}  // namespace seamless
