#include "core/timing.hpp"

#include <algorithm>
#include <fstream>

#include "core/cuda_check.hpp"
#include "core/error.hpp"
#include "core/output_file.hpp"

namespace seamless {

struct StageTimer::Pending {
  std::string stage;
  std::chrono::steady_clock::time_point t0, t1;
#if SEAMLESS_HAS_CUDA
  cudaEvent_t e0 = nullptr, e1 = nullptr;
#endif
  bool open = true;
};

StageTimer::StageTimer(Device d) : device_(d) {}

StageTimer::~StageTimer() {
  for (Pending* p : pending_) {
#if SEAMLESS_HAS_CUDA
    if (p->e0) cudaEventDestroy(p->e0);
    if (p->e1) cudaEventDestroy(p->e1);
#endif
    delete p;
  }
}

void StageTimer::begin(const std::string& stage) {
  auto* p = new Pending{stage, std::chrono::steady_clock::now(), {}};
#if SEAMLESS_HAS_CUDA
  if (device_ == Device::CUDA) {
    SEAMLESS_CUDA_CHECK(cudaEventCreate(&p->e0));
    SEAMLESS_CUDA_CHECK(cudaEventCreate(&p->e1));
    SEAMLESS_CUDA_CHECK(cudaEventRecord(p->e0));
  }
#endif
  pending_.push_back(p);
}

void StageTimer::end(const std::string& stage) {
  for (auto it = pending_.rbegin(); it != pending_.rend(); ++it) {
    Pending* p = *it;
    if (p->open && p->stage == stage) {
      p->open = false;
      p->t1 = std::chrono::steady_clock::now();
#if SEAMLESS_HAS_CUDA
      if (device_ == Device::CUDA) SEAMLESS_CUDA_CHECK(cudaEventRecord(p->e1));
#endif
      return;
    }
  }
  throw Error("StageTimer::end(\"" + stage + "\") without a matching begin");
}

void StageTimer::end_frame(std::int64_t frame) {
  for (Pending* p : pending_) {
    if (p->open) throw Error("stage '" + p->stage + "' still open at the end of frame " + std::to_string(frame));
    double ms = std::chrono::duration<double, std::milli>(p->t1 - p->t0).count();
#if SEAMLESS_HAS_CUDA
    if (device_ == Device::CUDA) {
      float f = 0;
      SEAMLESS_CUDA_CHECK(cudaEventSynchronize(p->e1));
      SEAMLESS_CUDA_CHECK(cudaEventElapsedTime(&f, p->e0, p->e1));
      ms = f;
      cudaEventDestroy(p->e0);
      cudaEventDestroy(p->e1);
    }
#endif
    rows_.push_back({frame, p->stage, ms});
    delete p;
  }
  pending_.clear();
}

void StageTimer::write_csv(const std::string& path) const {
  {
    std::ofstream f(partial_path(path));
    if (!f) throw Error("cannot write timings to " + path);
    f << "frame,stage,ms\n";
    for (const Row& r : rows_) f << r.frame << ',' << r.stage << ',' << r.ms << '\n';
    f.close();
    if (!f) throw Error("error writing timings to " + path + " (disk full?)");
  }
  commit_partial(path);
}

DeviceMarks::DeviceMarks(Device d, int count) : device_(d), host_(count), events_(count, nullptr) {
#if SEAMLESS_HAS_CUDA
  if (d == Device::CUDA)
    for (void*& e : events_) {
      cudaEvent_t ev = nullptr;
      SEAMLESS_CUDA_CHECK(cudaEventCreate(&ev));
      e = ev;
    }
#endif
}

DeviceMarks::~DeviceMarks() {
#if SEAMLESS_HAS_CUDA
  for (void* e : events_)
    if (e) cudaEventDestroy(static_cast<cudaEvent_t>(e));
#endif
}

void DeviceMarks::mark(int k) {
#if SEAMLESS_HAS_CUDA
  if (device_ == Device::CUDA) {
    SEAMLESS_CUDA_CHECK(cudaEventRecord(static_cast<cudaEvent_t>(events_.at(k)), cudaStreamLegacy));
    return;
  }
#endif
  host_.at(k) = std::chrono::steady_clock::now();
}

double DeviceMarks::ms(int a, int b) const {
#if SEAMLESS_HAS_CUDA
  if (device_ == Device::CUDA) {
    auto ea = static_cast<cudaEvent_t>(events_.at(a)), eb = static_cast<cudaEvent_t>(events_.at(b));
    SEAMLESS_CUDA_CHECK(cudaEventSynchronize(eb));
    float f = 0;
    SEAMLESS_CUDA_CHECK(cudaEventElapsedTime(&f, ea, eb));
    return f;
  }
#endif
  return std::chrono::duration<double, std::milli>(host_.at(b) - host_.at(a)).count();
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

double StageTimer::median_ms(const std::string& stage) const {
  std::vector<double> v;
  for (const Row& r : rows_)
    if (r.stage == stage) v.push_back(r.ms);
  return median(v);
}

}  // namespace seamless

namespace seamless {
double measure_ms(Device d, const std::function<void()>& fn) {
#if SEAMLESS_HAS_CUDA
  if (d == Device::CUDA) {
    cudaEvent_t a, b;
    SEAMLESS_CUDA_CHECK(cudaEventCreate(&a));
    SEAMLESS_CUDA_CHECK(cudaEventCreate(&b));
    SEAMLESS_CUDA_CHECK(cudaEventRecord(a));
    fn();
    SEAMLESS_CUDA_CHECK(cudaEventRecord(b));
    SEAMLESS_CUDA_CHECK(cudaEventSynchronize(b));
    float ms = 0;
    SEAMLESS_CUDA_CHECK(cudaEventElapsedTime(&ms, a, b));
    cudaEventDestroy(a);
    cudaEventDestroy(b);
    return ms;
  }
#endif
  (void)d;
  auto t0 = std::chrono::steady_clock::now();
  fn();
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace seamless
