#include "core/step_graph.hpp"

#include <exception>
#include <utility>

#include "core/log.hpp"

namespace seamless {

StepGraph::StepGraph(Device d, std::string name) : dev_(d), name_(std::move(name)) {}
StepGraph::~StepGraph() = default;

void StepGraph::step(bool replay, const Key& key, const std::function<void()>& step) {
#if SEAMLESS_HAS_CUDA
  if (dev_ == Device::CUDA) {
    if (!stream_) stream_ = std::make_unique<CudaStream>();
    stream_->after_default();
    if (!(replay && replay_graph(key, step))) step();
    stream_->before_default();
    return;
  }
#endif
  (void)replay, (void)key;
  step();
}

#if SEAMLESS_HAS_CUDA
// Records the step (if the graph held is not for this key) and launches it; false where graphs
// are off after a failed recording, or the recording failed now.
bool StepGraph::replay_graph(const Key& key, const std::function<void()>& step) {
  if (failed_) return false;
  if (!graph_.ready() || !(key_ == key)) {
    try {
      graph_.begin_capture(*stream_);
      step();
      graph_.end_capture();
    } catch (const std::exception& e) {
      graph_.abort_capture();
      graph_.reset();
      failed_ = true;
      spdlog::warn("{}: capturing the step as a CUDA graph failed ({}); stepping without graphs", name_, e.what());
      return false;
    }
    key_ = key;
  }
  graph_.launch(*stream_);
  return true;
}
#else
bool StepGraph::replay_graph(const Key&, const std::function<void()>&) { return false; }
#endif

}  // namespace seamless
